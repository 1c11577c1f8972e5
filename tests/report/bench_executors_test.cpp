// One benchmark plan, run by executors other than the built-in pool (GNU parallel, xargs, a Slurm cluster of one
// node on this machine), must give the built-in runner's table, byte for byte except the timing columns; a job
// killed on the way is missing, `collect` says so, and running the plan again runs that job alone. Real child
// processes of the built CLI on the tiny matrix (one 1-s walking sequence, huber and full).
#include <fcntl.h>
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "report/bench_job.hpp"
#include "report/process_pool.hpp"
#include "file_text.hpp"

extern char** environ;

namespace varslam::report {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

const fs::path kCli = fs::path(VARSLAM_BINARY_DIR) / "bin" / "varslam";
const fs::path kPath = fs::path(VARSLAM_SHARED_DIR) / "trajectories" / "rgbd_dataset_freiburg3_sitting_static";

using test::slurp;

struct Shell {
  int exit_code = -1;
  std::string output;
};
// Runs a /bin/sh command line; its stdout and stderr come back.
Shell shell(const std::string& command, const fs::path& log) {
  const int status = std::system(("( " + command + " ) > " + shell_quote(log.string()) + " 2>&1").c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(log)};
}

bool on_path(const std::string& tool) { return std::system(("command -v " + tool + " >/dev/null 2>&1").c_str()) == 0; }

// The tiny matrix's options, for `varslam bench` and `varslam bench plan` alike.
std::string tiny_matrix(const fs::path& out, double seconds = 1.0) {
  return shell_join({"--scenarios", "walking", "--paths", kPath.string(), "--seeds", "1", "--seconds",
                     fmt::format("{}", seconds), "--configs", "huber,full", "--out", out.string()});
}

// A table.md without its first line (date, wall time, load) and with every timing cell (fps, tracking, Local BA
// and peer wall times: the machine's load, not the method) replaced by "t". Everything else stays byte for byte.
std::string table_without_timings(const std::string& table) {
  std::istringstream in(table.substr(table.find('\n') + 1));
  std::string out, line;
  std::vector<bool> timing;  // per column of the table being read
  std::vector<std::string> previous;
  const auto cells = [](const std::string& row) {
    std::vector<std::string> c;
    std::stringstream s(row);
    for (std::string cell; std::getline(s, cell, '|');) c.push_back(cell);
    return c;
  };
  while (std::getline(in, line)) {
    if (line.rfind("|---", 0) == 0) {  // the line under a header: which columns are timings
      timing.clear();
      for (const auto& h : previous) {
        const auto ends = [&h](const std::string& s) { return h.size() >= s.size() && h.compare(h.size() - s.size(), s.size(), s) == 0; };
        timing.push_back(ends(" fps ") || ends(" trk ms ") || ends(" LBA ms ") || ends(" s "));
      }
    } else if (line.rfind("| ", 0) == 0 && !timing.empty()) {
      std::vector<std::string> c = cells(line);
      line.clear();
      for (std::size_t i = 0; i < c.size(); ++i) line += (i ? "|" : "") + (i < timing.size() && timing[i] ? " t " : c[i]);
      line += "|";
    } else if (line.empty()) {
      timing.clear();
    }
    previous = cells(line);
    out += line + "\n";
  }
  return out;
}

// The built-in runner's table of the tiny matrix (the reference every executor must reproduce).
std::string built_in_table(const fs::path& root) {
  const fs::path out = root / "built_in";
  const Shell b = shell(shell_quote(kCli.string()) + " bench " + tiny_matrix(out) + " --jobs 2", root / "built_in.log");
  EXPECT_EQ(b.exit_code, 0) << b.output;
  return slurp(out / "table.md");
}

void expect_same_table(const std::string& reference, const std::string& table) {
  const std::string a = table_without_timings(reference), b = table_without_timings(table);
  EXPECT_EQ(a, b) << "built-in:\n" << reference << "\nexecutor:\n" << table;
  // The comparison compares something: ATE cells are there, timing cells were masked, no run failed or is missing.
  EXPECT_THAT(b, HasSubstr("\n| walking | fr3_sitting_static | 0.")) << b;
  EXPECT_THAT(b, HasSubstr("| t | t |")) << b;
  EXPECT_THAT(b, Not(HasSubstr("| fail"))) << b;
  EXPECT_THAT(table, Not(HasSubstr("missing"))) << table;
}

class BenchExecutors : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kCli)) GTEST_SKIP() << kCli << " not built (build the varslam_cli target first)";
    if (!fs::exists(kPath)) GTEST_SKIP() << "camera path " << kPath << " not found (../shared is absent)";
    root_ = fs::temp_directory_path() / ("varslam_bench_executors_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override {
    if (!root_.empty()) fs::remove_all(root_);
  }
  std::string cli() const { return shell_quote(kCli.string()); }
  // Every job of every stage through `executor`, which reads job numbers on stdin and appends each to its command.
  Shell run_stages(const fs::path& plan, const std::string& executor, const std::string& name) {
    const std::string q = shell_quote(plan.string());
    return shell("for s in 0 1; do " + cli() + " bench jobs " + q + " --stage $s | " + executor + " " + cli() +
                     " bench run-job " + q + " || exit 1; done",
                 root_ / (name + ".log"));
  }
  fs::path root_;
};

TEST_F(BenchExecutors, GnuParallelRunsThePlanToTheBuiltInRunnersTable) {
  if (!on_path("parallel")) GTEST_SKIP() << "GNU parallel is not installed (Debian package parallel; scripts/setup.sh)";
  const std::string reference = built_in_table(root_);
  const fs::path plan = root_ / "parallel";
  const Shell p = shell(cli() + " bench plan " + tiny_matrix(plan), root_ / "plan.log");
  ASSERT_EQ(p.exit_code, 0) << p.output;
  EXPECT_THAT(p.output, HasSubstr("bench plan: 3 jobs in 2 stages"));
  const Shell run = run_stages(plan, "parallel --will-cite -j 2", "parallel");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("bench run-job: job 0 (synth walking__fr3_sitting_static__s1__1s__at11.3) ok"));
  const Shell c = shell(cli() + " bench collect " + shell_quote(plan.string()), root_ / "collect.log");
  ASSERT_EQ(c.exit_code, 0) << c.output;
  expect_same_table(reference, slurp(plan / "table.md"));
  EXPECT_TRUE(fs::exists(plan / "index.html"));
  EXPECT_TRUE(fs::exists(plan / "runs" / "walking__fr3_sitting_static__s1__1s__at11.3" / "full" / "report.html"));
}

// Starts `varslam bench run-job DIR N` in a process group of its own, so that killing the group kills the job's
// child (varslam run) too, as a scheduler's cancel does.
pid_t start_job_in_own_group(const fs::path& plan, std::size_t n, const fs::path& log) {
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  const std::string number = std::to_string(n);
  std::vector<std::string> args{kCli.string(), "bench", "run-job", plan.string(), number};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  return rc == 0 ? pid : -1;
}

TEST_F(BenchExecutors, AJobKilledMidRunIsMissingAndRunningThePlanAgainRunsOnlyIt) {
  const fs::path plan = root_ / "killed";
  // 2-s sequences: the run takes long enough to be killed while it is running.
  ASSERT_EQ(shell(cli() + " bench plan " + tiny_matrix(plan, 2.0), root_ / "plan.log").exit_code, 0);
  const std::string q = shell_quote(plan.string());
  // Stage 0 and job 2 with plain xargs.
  const Shell x = shell(cli() + " bench jobs " + q + " --stage 0 | xargs -r -P 2 -n 1 " + cli() + " bench run-job " +
                            q + " && echo 2 | xargs -r -n 1 " + cli() + " bench run-job " + q,
                        root_ / "xargs.log");
  ASSERT_EQ(x.exit_code, 0) << x.output;
  const fs::path huber = plan / "runs" / "walking__fr3_sitting_static__s1__2s__at10.8" / "huber";
  const fs::path full_marker = huber.parent_path() / "full" / kJobMarkerFile;
  ASSERT_TRUE(fs::exists(full_marker));
  const auto full_written = fs::last_write_time(full_marker);

  // Job 1 (huber), killed with its child once `varslam run` holds its folder.
  const pid_t pid = start_job_in_own_group(plan, 1, root_ / "killed_job.log");
  ASSERT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!fs::exists(huber / ".varslam.lock") && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ::kill(-pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the job ended before it was killed:\n" << slurp(root_ / "killed_job.log");
  EXPECT_FALSE(fs::exists(huber / kJobMarkerFile));

  const Shell half = shell(cli() + " bench collect " + q, root_ / "collect_half.log");
  EXPECT_EQ(half.exit_code, 5) << half.output;
  EXPECT_THAT(half.output, HasSubstr("bench: 1 of 3 jobs have not run (or were stopped); the tables leave them out:\n"
                                     "  job 1 (run walking__fr3_sitting_static__s1__2s__at10.8 huber)\n"));
  EXPECT_THAT(half.output, HasSubstr("1 of 3 jobs missing"));
  EXPECT_THAT(slurp(plan / "table.md"), HasSubstr("1 runs (0 failed, 1 jobs missing)"));
  const Shell listed = shell(cli() + " bench jobs " + q + " --missing", root_ / "missing.log");
  EXPECT_EQ(listed.output, "1\n");

  // The plan again, every job: only job 1 runs.
  const Shell again = shell(cli() + " bench execute " + q + " -j 2", root_ / "execute.log");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_THAT(again.output, HasSubstr("(0 to generate, 1 cached), 2 configurations, 1 child processes"));
  EXPECT_THAT(again.output, HasSubstr("[1/1]"));
  EXPECT_THAT(again.output, HasSubstr("run walking__fr3_sitting_static__s1__2s__at10.8 huber  ATE"));
  EXPECT_EQ(fs::last_write_time(full_marker), full_written) << "job 2 ran again";
  // And through xargs: every job is complete, none runs.
  const Shell idle = run_stages(plan, "xargs -r -P 2 -n 1", "xargs_again");
  EXPECT_EQ(idle.exit_code, 0) << idle.output;
  std::size_t complete = 0;
  for (auto pos = idle.output.find("is complete already"); pos != std::string::npos;
       pos = idle.output.find("is complete already", pos + 1))
    ++complete;
  EXPECT_EQ(complete, 3u) << idle.output;
  EXPECT_EQ(fs::last_write_time(full_marker), full_written);

  const Shell whole = shell(cli() + " bench collect " + q, root_ / "collect.log");
  EXPECT_EQ(whole.exit_code, 0) << whole.output;
  EXPECT_THAT(slurp(plan / "table.md"), HasSubstr("2 runs (0 failed) in"));
}

TEST_F(BenchExecutors, BadInputIsAClearErrorNamingTheFileOrNumber) {
  const fs::path plan = root_ / "bad";
  ASSERT_EQ(shell(cli() + " bench plan " + tiny_matrix(plan), root_ / "plan.log").exit_code, 0);
  const std::string q = shell_quote(plan.string());
  const std::string file = (plan / "plan.jsonl").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"bench run-job " + q + " 3", "job 3: " + file + " has 3 jobs, numbered 0 to 2"},
      {"bench run-job " + q + " -1", "job number '-1' is not a non-negative integer"},
      {"bench run-job " + q + " 1", "needs job 0 (synth walking__fr3_sitting_static__s1__1s__at11.3), which has not run"},
      {"bench jobs " + q + " --stage 2", "--stage 2: " + file + " has stages 0 to 1"},
      {"bench collect " + shell_quote((root_ / "nowhere").string()), (root_ / "nowhere").string() + ": no such folder"},
      {"bench execute " + shell_quote(root_.string()), (root_ / "plan.jsonl").string() + ": not found"}};
  for (const auto& [args, message] : cases) {
    const Shell s = shell(cli() + " " + args, root_ / "bad.log");
    EXPECT_EQ(s.exit_code, 2) << args << "\n" << s.output;
    EXPECT_THAT(s.output, HasSubstr(message)) << args;
  }
  // A plan of another version.
  std::string text = slurp(plan / "plan.jsonl");
  text.replace(text.find("\"version\":1"), 11, "\"version\":9");
  std::ofstream(plan / "plan.jsonl") << text;
  const Shell v = shell(cli() + " bench run-job " + q + " 0", root_ / "version.log");
  EXPECT_EQ(v.exit_code, 2) << v.output;
  EXPECT_THAT(v.output, HasSubstr(file + " line 1: key 'version' is 9, this varslam reads plan version 1"));
}

// Stops the one-node cluster however the test ends.
struct ClusterGuard {
  fs::path dir;
  ~ClusterGuard() {
    if (!dir.empty())
      (void)std::system(("bash " + shell_quote(VARSLAM_SOURCE_DIR "/tests/report/slurm_one_node.sh") + " stop " +
                         shell_quote(dir.string()) + " >/dev/null 2>&1")
                            .c_str());
  }
};

TEST_F(BenchExecutors, ASlurmClusterOfOneNodeRunsThePlanAsJobArraysToTheSameTable) {
  const fs::path cluster = root_ / "cluster";
  ClusterGuard guard{cluster};
  const Shell up = shell("bash " + shell_quote(VARSLAM_SOURCE_DIR "/tests/report/slurm_one_node.sh") + " start " +
                             shell_quote(cluster.string()),
                         root_ / "cluster_start.log");
  if (up.exit_code == 77) GTEST_SKIP() << "no Slurm cluster here: " << up.output;
  ASSERT_EQ(up.exit_code, 0) << up.output;
  const std::string slurm_conf = "SLURM_CONF=" + shell_quote((cluster / "slurm.conf").string()) + " ";

  const std::string reference = built_in_table(root_);
  const fs::path plan = root_ / "slurm";
  const Shell p = shell(cli() + " bench plan --slurm " + tiny_matrix(plan), root_ / "plan.log");
  ASSERT_EQ(p.exit_code, 0) << p.output;
  const std::string stage1 = slurp(plan / "slurm" / "stage1.sbatch");
  EXPECT_THAT(stage1, HasSubstr("#SBATCH --array=1-2\n"));
  EXPECT_THAT(stage1, HasSubstr("#SBATCH --mem=2048\n"));
  // --wait: each sbatch returns when its array has ended; stage 1 was submitted after stage 0's end.
  const Shell submit = shell(slurm_conf + "timeout 240 sh " + shell_quote((plan / "slurm" / "submit.sh").string()) +
                                 " --wait",
                             root_ / "submit.log");
  ASSERT_EQ(submit.exit_code, 0) << submit.output << "\n" << slurp(cluster / "log" / "slurmctld.log");
  EXPECT_THAT(submit.output, HasSubstr("stage 0: Slurm job "));
  EXPECT_THAT(submit.output, HasSubstr("stage 1: Slurm job "));
  std::string task_logs;
  for (const auto& f : fs::directory_iterator(plan / "slurm" / "logs")) task_logs += slurp(f.path());
  EXPECT_THAT(task_logs, HasSubstr("bench run-job: job 0 (synth"));
  EXPECT_THAT(task_logs, HasSubstr("bench run-job: job 2 (run walking__fr3_sitting_static__s1__1s__at11.3 full) ok"));
  const Shell c = shell(cli() + " bench collect " + shell_quote(plan.string()), root_ / "collect.log");
  ASSERT_EQ(c.exit_code, 0) << c.output;
  expect_same_table(reference, slurp(plan / "table.md"));
}

}  // namespace
}  // namespace varslam::report
