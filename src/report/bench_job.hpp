#pragma once
// One job of a benchmark plan: how far it got, and running it. Running is idempotent: a complete job is not run
// again, so any executor may start every job of a plan again and only the missing ones run. A job that ended
// leaves bench_job.json (its marker) in its output folder; a job killed on the way leaves none and stays missing.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "report/bench_plan.hpp"

namespace varslam::report {

/// In a generated sequence's folder: the content key it was generated for (bench_matrix synth_cache_key).
inline constexpr const char* kCacheKeyFile = "bench_cache_key.txt";
/// In every job's output folder: how the job ended.
inline constexpr const char* kJobMarkerFile = "bench_job.json";

/// What a job's marker records.
struct JobMarker {
  std::string plan_id;        // the plan whose job wrote it
  std::size_t job = 0;
  bool ok = false;
  int exit_code = -1;         // the command's exit status (128 + signal when killed); -1 when it did not start
  double wall_seconds = 0.0;  // the command's, start to exit
  std::string error;          // why not ok
  std::string finished_utc;
};

enum class JobState {
  Missing,   // never ran, or was killed before it ended
  Complete,  // ended well (a synth job: its sequence is in the cache, whoever generated it)
  Failed     // ended badly, or was skipped because a job it needs failed; running it again retries it
};
std::string state_name(JobState state);

/// "job 3 (run walking__fr3_sitting_static__s1__2s__at10.8 huber)", for messages.
std::string describe_job(const PlanJob& job);

/// The job's marker, when it has one (any plan's).
std::optional<JobMarker> read_job_marker(const PlanJob& job);
JobState job_state(const BenchPlan& plan, const PlanJob& job);

/// A sequence folder that a benchmark generated or tried to (synth's scenario.json, our key file or marker): only
/// such a folder is ever replaced; any other is the user's.
bool generated_by_bench(const std::filesystem::path& sequence_dir);

/// A generated sequence matches its cached folder (same content key, ground truth present).
bool cached_sequence_matches(const SequenceSpec& seq);

/// Runs job `number` unless it is complete; its command's output goes to the job's log file. Returns the job's
/// marker (also when it was complete already, then with `ok` and the earlier figures). A job whose needed job
/// failed is recorded as failed ("skipped: a task it needs failed") without running. InputError when the number is
/// out of range or a needed job has not run yet.
JobMarker run_bench_job(const BenchPlan& plan, std::size_t number,
                        const std::function<void(const std::string&)>& log);

/// Records the job as failed without running it: a job it needs failed (kSkippedError), or the executor's
/// `run-job` process ended before it could record the job itself.
JobMarker record_failed_job(const BenchPlan& plan, const PlanJob& job, const std::string& error);
inline constexpr const char* kSkippedError = "skipped: a task it needs failed";

/// A planned run or peer folder starts empty of an earlier benchmark's outputs and marker.
void clear_job_outputs(const BenchPlan& plan, const PlanJob& job);
/// Makes a cached sequence count as missing, so its synth job generates it again (bench --fresh).
void forget_cached_sequence(const PlanJob& synth_job);

}  // namespace varslam::report
