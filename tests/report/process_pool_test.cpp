#include "report/process_pool.hpp"

#include <gtest/gtest.h>

#include <fstream>

namespace varslam::report {
namespace {
namespace fs = std::filesystem;
using State = ProcessOutcome::State;

ProcessTask sh(const std::string& script, const fs::path& log = {}, std::vector<std::size_t> after = {}) {
  return {{"/bin/sh", "-c", script}, log, std::move(after)};
}

TEST(ProcessPool, RunsChildrenCapturesOutputAndExitCodes) {
  const auto dir = fs::temp_directory_path() / "varslam_process_pool_test";
  fs::create_directories(dir);
  std::vector<std::size_t> finished_order;
  const auto outcomes = run_processes({sh("echo hello; echo oops >&2", dir / "a.log"), sh("exit 3"),
                                       sh("kill -9 $$")},
                                      2, [&](std::size_t i, const ProcessOutcome&, std::size_t) { finished_order.push_back(i); });
  ASSERT_EQ(outcomes.size(), 3u);
  EXPECT_EQ(outcomes[0].state, State::Succeeded);
  EXPECT_EQ(outcomes[0].exit_code, 0);
  EXPECT_EQ(outcomes[1].state, State::Failed);
  EXPECT_EQ(outcomes[1].exit_code, 3);
  EXPECT_EQ(outcomes[2].state, State::Failed);
  EXPECT_EQ(outcomes[2].exit_code, 128 + 9);
  EXPECT_EQ(finished_order.size(), 3u);
  std::ifstream log(dir / "a.log");
  const std::string text{std::istreambuf_iterator<char>(log), std::istreambuf_iterator<char>()};
  EXPECT_EQ(text, "hello\noops\n");
  fs::remove_all(dir);
}

TEST(ProcessPool, DependentsWaitForAndAreSkippedAfterFailure) {
  const auto dir = fs::temp_directory_path() / "varslam_process_pool_dep_test";
  fs::create_directories(dir);
  const auto marker = (dir / "first_done").string();
  // Task 1 only succeeds if task 0 finished before it started, even with free slots.
  const auto outcomes = run_processes({sh("sleep 0.2; touch " + marker), sh("test -f " + marker, {}, {0}),
                                       sh("exit 1"), sh("true", {}, {2}), sh("true", {}, {3})},
                                      4);
  EXPECT_EQ(outcomes[0].state, State::Succeeded);
  EXPECT_EQ(outcomes[1].state, State::Succeeded);
  EXPECT_EQ(outcomes[2].state, State::Failed);
  EXPECT_EQ(outcomes[3].state, State::Skipped);
  EXPECT_EQ(outcomes[4].state, State::Skipped);  // transitively
  fs::remove_all(dir);
}

TEST(ProcessPool, NeverMoreThanMaxParallel) {
  const auto dir = fs::temp_directory_path() / "varslam_process_pool_par_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // Each child creates a token, checks how many exist, then removes it: with one slot there is never a second.
  const std::string script = "d=" + dir.string() + "; touch $d/$$; n=$(ls $d | wc -l); sleep 0.05; rm $d/$$; test $n -eq 1";
  std::vector<ProcessTask> tasks(4, sh(script));
  for (const auto& o : run_processes(tasks, 1)) EXPECT_EQ(o.state, State::Succeeded);
  fs::remove_all(dir);
}

TEST(ProcessPool, TimeoutKillsAndFails) {
  ProcessTask slow = sh("sleep 30");
  slow.timeout_seconds = 0.2;
  const auto outcomes = run_processes({slow, sh("true")}, 2);
  EXPECT_EQ(outcomes[0].state, State::Failed);
  EXPECT_NE(outcomes[0].error.find("timed out"), std::string::npos);
  EXPECT_LT(outcomes[0].wall_seconds, 10.0);  // killed, not waited for
  EXPECT_EQ(outcomes[1].state, State::Succeeded);
}

TEST(ProcessPool, MissingProgramFailsWithoutThrowing) {
  const auto outcomes = run_processes({{{"/nonexistent/program"}, {}, {}}}, 1);
  EXPECT_EQ(outcomes[0].state, State::Failed);
}

TEST(ShellQuote, QuotesOnlyWhatNeedsIt) {
  EXPECT_EQ(shell_quote("/a/b-c_d.txt"), "/a/b-c_d.txt");
  EXPECT_EQ(shell_quote("a b"), "'a b'");
  EXPECT_EQ(shell_quote("it's"), "'it'\\''s'");
  EXPECT_EQ(shell_quote(""), "''");
  EXPECT_EQ(shell_join({"x", "--set", "a=b c"}), "x --set 'a=b c'");
}

TEST(SelfExecutable, IsThisTestBinary) {
  EXPECT_NE(self_executable().filename().string().find("test_report"), std::string::npos);
}

}  // namespace
}  // namespace varslam::report
