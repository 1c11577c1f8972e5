// The benchmark plan, its jobs and its collection, with a stand-in for the varslam binary (a shell script that
// writes what synth and run write, in milliseconds), so every state of a job is reached fast.
#include "report/bench_plan.hpp"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#include <fstream>

#include "core/error.hpp"
#include "io/trajectory_io.hpp"
#include "report/bench_collect.hpp"
#include "report/bench_job.hpp"
#include "report/bench_plan_file.hpp"
#include "report/bench_slurm.hpp"
#include "file_text.hpp"

namespace varslam::report {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

using test::slurp;

// `synth --out DIR` writes a ground truth and scenario.json; `run --out DIR` writes metrics.json with an ATE of
// 1 cm. FAKE_VARSLAM_FAIL=synth|run makes that command fail with exit code 3.
constexpr const char* kFakeVarslam = R"(#!/bin/sh
cmd=$1; shift
out=
while [ $# -gt 0 ]; do [ "$1" = --out ] && out=$2; shift; done
[ "$FAKE_VARSLAM_FAIL" = "$cmd" ] && exit 3
mkdir -p "$out"
case $cmd in
  synth) echo '1.0 0 0 0 0 0 0 1' > "$out/groundtruth.txt"; echo '{}' > "$out/scenario.json" ;;
  run) echo '{"ate": {"rmse": 0.01, "max": 0.02, "correct_rate": 1}, "fps": 30, "wall_seconds": 0.5, "timings": {"tracking": {"median_ms": 5}}}' > "$out/metrics.json" ;;
esac
)";

class BenchPlanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("varslam_bench_plan_test_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    Trajectory t;
    for (int i = 0; i <= 100; ++i) {  // 10 s at 10 Hz
      StampedPose p;
      p.timestamp = 100.0 + 0.1 * i;
      t.push_back(p);
    }
    write_tum_trajectory(t, root_ / "camera_path.txt");
    std::ofstream(root_ / "fake_varslam") << kFakeVarslam;
    fs::permissions(root_ / "fake_varslam", fs::perms::owner_all);
    options_.scenarios = {"walking"};
    options_.paths = {(root_ / "camera_path.txt").string()};
    options_.seeds = {1};
    options_.seconds = 2.0;
    options_.configs = {"huber", "full"};
    options_.out = root_ / "plan";
    options_.executable = root_ / "fake_varslam";
    options_.command_line = "varslam bench (test)";
    options_.log = [](const std::string&) {};
    ::unsetenv("FAKE_VARSLAM_FAIL");
  }
  void TearDown() override {
    ::unsetenv("FAKE_VARSLAM_FAIL");
    fs::remove_all(root_);
  }
  BenchPlan planned() {
    const auto folder = claim_bench_folder(options_.out);
    BenchPlan p = make_bench_plan(options_);
    write_bench_plan(p, false);
    return p;
  }
  void rewrite_line(std::size_t line_index, const std::function<void(nlohmann::json&)>& change) {
    const fs::path file = options_.out / kBenchPlanFile;
    std::istringstream in(slurp(file));
    std::string text, line;
    for (std::size_t i = 0; std::getline(in, line); ++i) {
      if (i == line_index) {
        auto j = nlohmann::json::parse(line);
        change(j);
        line = j.dump();
      }
      text += line + "\n";
    }
    std::ofstream(file) << text;
  }
  std::string read_error() {
    try {
      read_bench_plan(options_.out);
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  }
  fs::path root_;
  BenchOptions options_;
  const std::function<void(const std::string&)> quiet_ = [](const std::string&) {};
};

TEST_F(BenchPlanTest, SequencesFirstThenRunsThatNeedThem) {
  const BenchPlan p = planned();
  ASSERT_EQ(p.jobs.size(), 3u);
  EXPECT_EQ(p.jobs[0].kind, PlanJob::Kind::Synth);
  EXPECT_EQ(p.jobs[0].stage, 0);
  EXPECT_TRUE(p.jobs[0].needs.empty());
  EXPECT_EQ(p.jobs[0].argv[1], "synth");
  for (std::size_t n : {1u, 2u}) {
    EXPECT_EQ(p.jobs[n].kind, PlanJob::Kind::Run);
    EXPECT_EQ(p.jobs[n].stage, 1);
    EXPECT_EQ(p.jobs[n].needs, std::vector<std::size_t>{0});
    EXPECT_EQ(p.jobs[n].out_dir, p.dir / "runs" / p.jobs[0].sequence / p.jobs[n].config);
    EXPECT_GT(p.jobs[n].time_limit_seconds, 0.0);
    EXPECT_GT(p.jobs[n].memory_mb, 0);
  }
  EXPECT_EQ(p.jobs[1].config, "huber");
  EXPECT_THAT(p.jobs[1].command, HasSubstr("--set tracking.kernel=huber"));
  EXPECT_EQ(p.jobs[2].detector, "boxes");
  EXPECT_EQ(jobs_of_stage(p, 1), (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(stage_count(p), 2);
}

TEST_F(BenchPlanTest, WrittenPlanReadsBackTheSame) {
  const BenchPlan p = planned();
  const BenchPlan back = read_bench_plan(options_.out);
  EXPECT_EQ(back.id, p.id);
  EXPECT_EQ(back.executable, p.executable);
  EXPECT_EQ(back.configs, p.configs);
  ASSERT_EQ(back.sequences.size(), 1u);
  EXPECT_EQ(to_json(back.sequences[0]), to_json(p.sequences[0]));
  ASSERT_EQ(back.jobs.size(), p.jobs.size());
  for (std::size_t i = 0; i < p.jobs.size(); ++i) EXPECT_EQ(to_json(back.jobs[i]), to_json(p.jobs[i])) << i;
  // One line per job after the header.
  const std::string text = slurp(options_.out / kBenchPlanFile);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 4);
  EXPECT_THAT(text, HasSubstr("{\"format\":\"varslam bench plan\",\"version\":1,\"id\""));
}

TEST_F(BenchPlanTest, BadPlansAreErrorsNamingFileAndKey) {
  (void)planned();
  const std::string file = (options_.out / kBenchPlanFile).string();
  rewrite_line(0, [](nlohmann::json& h) { h["version"] = 2; });
  EXPECT_THAT(read_error(), HasSubstr(file + " line 1: key 'version' is 2, this varslam reads plan version 1"));
  rewrite_line(0, [](nlohmann::json& h) { h["version"] = 1; });
  rewrite_line(2, [](nlohmann::json& j) { j.erase("out"); });
  EXPECT_THAT(read_error(), HasSubstr(file + " line 3: key 'out' is missing"));
  rewrite_line(2, [](nlohmann::json& j) { j["out"] = 7; });
  EXPECT_THAT(read_error(), HasSubstr(file + " line 3: key 'out' has the wrong type (number)"));
  (void)planned();
  rewrite_line(2, [](nlohmann::json& j) { j["needs"] = {2}; });
  EXPECT_THAT(read_error(), HasSubstr(file + " line 3: key 'needs' names job 2, which is not an earlier job"));
  (void)planned();
  rewrite_line(0, [](nlohmann::json& h) { h["jobs"] = 5; });
  EXPECT_THAT(read_error(), HasSubstr("announces 5 jobs, the file has 3"));
  rewrite_line(0, [](nlohmann::json& h) { h["format"] = "something else"; });
  EXPECT_THAT(read_error(), HasSubstr("not a varslam bench plan"));
  std::ofstream(options_.out / kBenchPlanFile) << "{ not json\n";
  EXPECT_THAT(read_error(), HasSubstr(file + " line 1: not JSON"));

  const BenchPlan p = planned();
  try {
    (void)p.job(3);
    FAIL() << "job 3 of 3 must be refused";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("job 3: " + file + " has 3 jobs, numbered 0 to 2"));
  }
  fs::remove(options_.out / kBenchPlanFile);
  EXPECT_THAT(read_error(), HasSubstr(file + ": not found; write a plan with varslam bench plan"));
  EXPECT_THROW(read_bench_plan(root_ / "no_such_folder"), InputError);
}

TEST_F(BenchPlanTest, JobsRunOnceInOrderAndLeaveMarkers) {
  const BenchPlan p = planned();
  EXPECT_EQ(job_state(p, p.jobs[1]), JobState::Missing);
  try {
    run_bench_job(p, 1, quiet_);
    FAIL() << "a run before its sequence must be refused";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("job 1 (run walking__camera_path__s1__2s__at4 huber) needs job 0 (synth"));
    EXPECT_THAT(e.what(), HasSubstr("run stage 0 first"));
  }
  EXPECT_TRUE(run_bench_job(p, 0, quiet_).ok);
  EXPECT_EQ(job_state(p, p.jobs[0]), JobState::Complete);
  EXPECT_TRUE(fs::exists(p.jobs[0].out_dir / kCacheKeyFile));
  const JobMarker first = run_bench_job(p, 1, quiet_);
  EXPECT_TRUE(first.ok);
  EXPECT_EQ(first.plan_id, p.id);
  EXPECT_EQ(job_state(p, p.jobs[1]), JobState::Complete);
  // Again: nothing runs, the marker stays the first run's.
  const auto marker_time = fs::last_write_time(p.jobs[1].out_dir / kJobMarkerFile);
  fs::remove(p.jobs[1].out_dir / "metrics.json");  // would be rewritten if the job ran again
  EXPECT_TRUE(run_bench_job(p, 1, quiet_).ok);
  EXPECT_FALSE(fs::exists(p.jobs[1].out_dir / "metrics.json"));
  EXPECT_EQ(fs::last_write_time(p.jobs[1].out_dir / kJobMarkerFile), marker_time);

  // A new plan into the same folder does not take the old plan's markers for its own; the sequence is cached.
  const BenchPlan again = planned();
  EXPECT_EQ(job_state(again, again.jobs[0]), JobState::Complete);
  EXPECT_EQ(job_state(again, again.jobs[1]), JobState::Missing);
}

TEST_F(BenchPlanTest, AJobRunningElsewhereIsNotStartedTwice) {
  const BenchPlan p = planned();
  const fs::path lock = p.jobs[0].log_file.string() + ".lock";
  fs::create_directories(lock.parent_path());
  const int fd = ::open(lock.c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);  // another executor's run-job of job 0
  try {
    run_bench_job(p, 0, quiet_);
    ADD_FAILURE() << "a job whose lock is held must not run";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("job 0 (synth walking__camera_path__s1__2s__at4) is running in another process"));
  }
  EXPECT_FALSE(fs::exists(p.jobs[0].out_dir / "groundtruth.txt"));
  ::close(fd);
  EXPECT_TRUE(run_bench_job(p, 0, quiet_).ok);
}

TEST_F(BenchPlanTest, FailuresAreRecordedAndTheirDependentsSkipped) {
  const BenchPlan p = planned();
  ::setenv("FAKE_VARSLAM_FAIL", "synth", 1);
  const JobMarker synth = run_bench_job(p, 0, quiet_);
  EXPECT_FALSE(synth.ok);
  EXPECT_EQ(synth.exit_code, 3);
  EXPECT_EQ(job_state(p, p.jobs[0]), JobState::Failed);
  const JobMarker run = run_bench_job(p, 1, quiet_);
  EXPECT_FALSE(run.ok);
  EXPECT_EQ(run.error, kSkippedError);
  EXPECT_EQ(job_state(p, p.jobs[1]), JobState::Failed);
  // A failed job runs again (and now works).
  ::unsetenv("FAKE_VARSLAM_FAIL");
  EXPECT_TRUE(run_bench_job(p, 0, quiet_).ok);
  EXPECT_TRUE(run_bench_job(p, 1, quiet_).ok);
}

TEST_F(BenchPlanTest, CollectOnAHalfDonePlanNamesTheMissingJobs) {
  const BenchPlan p = planned();
  run_bench_job(p, 0, quiet_);
  run_bench_job(p, 2, quiet_);
  std::vector<std::string> lines;
  CollectOptions c;
  c.log = [&lines](const std::string& l) { lines.push_back(l); };
  const BenchOutcome half = collect_benchmark(p, c);
  EXPECT_EQ(half.missing, std::vector<std::size_t>{1});
  EXPECT_EQ(half.runs, 1u);
  EXPECT_EQ(half.results["missing_jobs"], nlohmann::json::array({1}));
  ASSERT_GE(lines.size(), 3u);
  EXPECT_THAT(lines[lines.size() - 2], HasSubstr("1 of 3 jobs have not run"));
  EXPECT_THAT(lines.back(), HasSubstr("job 1 (run walking__camera_path__s1__2s__at4 huber)"));
  const std::string table = slurp(p.dir / "table.md");
  EXPECT_THAT(table, HasSubstr("1 runs (0 failed, 1 jobs missing)"));
  EXPECT_THAT(table, HasSubstr("| walking |  |  |  |  |  | 1.00 | 2.00 | 100.0 | 30.0 | 5.0 |"));

  run_bench_job(p, 1, quiet_);
  const BenchOutcome whole = collect_benchmark(p, c);
  EXPECT_TRUE(whole.missing.empty());
  EXPECT_EQ(whole.runs, 2u);
  EXPECT_THAT(slurp(p.dir / "table.md"), HasSubstr("2 runs (0 failed) in"));
}

TEST_F(BenchPlanTest, SlurmScriptsOneArrayPerStageWithItsLimits) {
  EXPECT_EQ(slurm_array_spec({0, 1, 2, 5, 7, 8}), "0-2,5,7-8");
  EXPECT_EQ(slurm_array_spec({4}), "4");
  const BenchPlan p = planned();
  const std::string s1 = slurm_stage_script(p, 1);
  EXPECT_THAT(s1, HasSubstr("#SBATCH --array=1-2\n"));
  EXPECT_THAT(s1, HasSubstr(fmt::format("#SBATCH --mem={}\n", p.jobs[1].memory_mb)));
  EXPECT_THAT(s1, HasSubstr(fmt::format("#SBATCH --time={}\n",
                                        static_cast<long>(std::ceil(p.jobs[1].time_limit_seconds / 60)))));
  EXPECT_THAT(s1, HasSubstr("bench run-job " + p.dir.string() + " \"$SLURM_ARRAY_TASK_ID\""));
  EXPECT_THAT(slurm_stage_script(p, 0), HasSubstr("#SBATCH --array=0\n"));
  EXPECT_THROW(slurm_stage_script(p, 2), InputError);
  const fs::path submit = write_slurm_scripts(p);
  EXPECT_TRUE(fs::exists(p.dir / "slurm" / "stage0.sbatch"));
  EXPECT_TRUE(fs::is_directory(p.dir / "slurm" / "logs"));
  const std::string text = slurp(submit);
  EXPECT_THAT(text, HasSubstr("--dependency=afterany:$previous"));
  EXPECT_THAT(text, HasSubstr("stage1.sbatch"));
}

}  // namespace
}  // namespace varslam::report
