#include "report/bench_job.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <unistd.h>

#include "core/error.hpp"
#include "io/output_folder.hpp"
#include "report/bench_files.hpp"
#include "report/process_pool.hpp"
#include "report/run_report.hpp"

namespace varslam::report {
namespace fs = std::filesystem;
namespace {

nlohmann::json to_json(const JobMarker& m) {
  return {{"plan", m.plan_id},       {"job", m.job},     {"ok", m.ok},
          {"exit_code", m.exit_code}, {"wall_seconds", m.wall_seconds}, {"error", m.error},
          {"finished_utc", m.finished_utc}};
}

JobMarker write_marker(const BenchPlan& plan, const PlanJob& job, bool ok, int exit_code, double wall,
                       const std::string& error) {
  JobMarker m{plan.id, job.number, ok, exit_code, wall, error, utc_now_iso8601()};
  fs::create_directories(job.out_dir);
  write_text_file(job.out_dir / kJobMarkerFile, to_json(m).dump(1) + "\n");
  return m;
}

// Held while a job runs: a second executor starting the same job (a leftover Slurm task beside GNU parallel, two
// `bench execute`) is refused instead of running it twice into one folder. An flock is released by the kernel
// when its process dies, so a killed job leaves no stale lock. Beside the log, which outlives a synth's folder.
class JobLock {
 public:
  explicit JobLock(const PlanJob& job) : file_(job.log_file.string() + ".lock") {
    fs::create_directories(job.log_file.parent_path());
    fd_ = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw InputError(fmt::format("{}: cannot create the job's lock file", file_));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      throw InputError(fmt::format("{} is running in another process ({} is held); let that one finish",
                                   describe_job(job), file_));
    }
  }
  ~JobLock() {
    ::flock(fd_, LOCK_UN);
    ::close(fd_);
  }
  JobLock(const JobLock&) = delete;
  JobLock& operator=(const JobLock&) = delete;

 private:
  std::string file_;
  int fd_ = -1;
};

// Before a job runs: nothing of an earlier attempt may pass for its result.
void prepare_job(const BenchPlan& plan, const PlanJob& job, const SequenceSpec& seq) {
  if (job.kind == PlanJob::Kind::Synth) {
    if (fs::exists(seq.dir)) {
      if (!generated_by_bench(seq.dir))
        throw InputError(seq.dir.string() + ": exists and is not a cached benchmark sequence; remove it");
      fs::remove_all(seq.dir);
    }
  } else {
    clear_job_outputs(plan, job);
  }
  fs::create_directories(job.log_file.parent_path());
}

// After the command succeeded: the synth's cache key, a run's report page.
void finish_job(const PlanJob& job, const SequenceSpec& seq, const std::function<void(const std::string&)>& log) {
  if (job.kind == PlanJob::Kind::Synth) {
    write_text_file(seq.dir / kCacheKeyFile, synth_cache_key(seq));
  } else if (job.kind == PlanJob::Kind::Run && fs::exists(job.out_dir / "metrics.json")) {
    try {
      write_run_report(job.out_dir, seq.dir, job.out_dir / "report.html");
    } catch (const InputError& e) {
      log(fmt::format("bench: report for {} failed: {}", job.out_dir.string(), e.what()));
    }
  }
}

}  // namespace

std::string describe_job(const PlanJob& job) {
  std::string s = fmt::format("job {} ({} {}", job.number, kind_name(job.kind), job.sequence);
  if (job.kind == PlanJob::Kind::Run) s += " " + job.config;
  return s + ")";
}

std::string state_name(JobState state) {
  switch (state) {
    case JobState::Missing: return "missing";
    case JobState::Complete: return "complete";
    case JobState::Failed: return "failed";
  }
  return "?";
}

std::optional<JobMarker> read_job_marker(const PlanJob& job) {
  const fs::path file = job.out_dir / kJobMarkerFile;
  if (!fs::exists(file)) return std::nullopt;
  try {
    const auto j = nlohmann::json::parse(read_text_file(file));
    JobMarker m;
    m.plan_id = j.at("plan").get<std::string>();
    m.job = j.at("job").get<std::size_t>();
    m.ok = j.at("ok").get<bool>();
    m.exit_code = j.at("exit_code").get<int>();
    m.wall_seconds = j.at("wall_seconds").get<double>();
    m.error = j.at("error").get<std::string>();
    m.finished_utc = j.at("finished_utc").get<std::string>();
    return m;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;  // a marker cut short or of another version: the job counts as not run
  }
}

bool generated_by_bench(const fs::path& dir) {
  return fs::exists(dir / kCacheKeyFile) || fs::exists(dir / "scenario.json") || fs::exists(dir / kJobMarkerFile);
}

bool cached_sequence_matches(const SequenceSpec& s) {
  return fs::exists(s.dir / kCacheKeyFile) && fs::exists(s.dir / "groundtruth.txt") &&
         read_text_file(s.dir / kCacheKeyFile) == synth_cache_key(s);
}

JobState job_state(const BenchPlan& plan, const PlanJob& job) {
  if (job.kind == PlanJob::Kind::Synth && cached_sequence_matches(plan.sequence(job.sequence)))
    return JobState::Complete;
  const auto m = read_job_marker(job);
  // A marker of another plan (an earlier benchmark into the same folder, another plan's synth) says nothing here.
  if (!m || m->plan_id != plan.id || m->job != job.number) return JobState::Missing;
  if (!m->ok) return JobState::Failed;
  // A synth job that ended well but whose sequence is gone or changed since.
  return job.kind == PlanJob::Kind::Synth ? JobState::Missing : JobState::Complete;
}

JobMarker run_bench_job(const BenchPlan& plan, std::size_t number, const std::function<void(const std::string&)>& log) {
  const PlanJob& job = plan.job(number);
  const SequenceSpec& seq = plan.sequence(job.sequence);
  const JobLock lock(job);  // before the state is read: a job that another process just finished is not run again
  if (job_state(plan, job) == JobState::Complete) {
    log(fmt::format("bench: {} is complete already", describe_job(job)));
    auto m = read_job_marker(job);
    return m ? *m : JobMarker{plan.id, job.number, true, 0, 0.0, "", ""};
  }
  for (const std::size_t n : job.needs) {
    const PlanJob& need = plan.job(n);
    const JobState s = job_state(plan, need);
    if (s == JobState::Failed) return record_failed_job(plan, job, kSkippedError);
    if (s == JobState::Missing)
      throw InputError(fmt::format("{} needs {}, which has not run (or was stopped): run stage {} first",
                                   describe_job(job), describe_job(need), need.stage));
  }
  prepare_job(plan, job, seq);
  const std::vector<ProcessOutcome> outcome =
      run_processes({{job.argv, job.log_file, {}, job.timeout_seconds}}, 1);
  const ProcessOutcome& o = outcome.front();
  const bool ok = o.state == ProcessOutcome::State::Succeeded;
  if (ok) finish_job(job, seq, log);
  return write_marker(plan, job, ok, o.exit_code, o.wall_seconds, o.error);
}

JobMarker record_failed_job(const BenchPlan& plan, const PlanJob& job, const std::string& error) {
  clear_job_outputs(plan, job);
  return write_marker(plan, job, false, -1, 0.0, error);
}

void clear_job_outputs(const BenchPlan& plan, const PlanJob& job) {
  fs::remove(job.out_dir / kJobMarkerFile);
  if (job.kind == PlanJob::Kind::Run) remove_earlier_outputs(job.out_dir);
  if (job.kind == PlanJob::Kind::Peer) fs::remove(job.out_dir / plan.peer_trajectory);
}

void forget_cached_sequence(const PlanJob& synth_job) {
  fs::remove(synth_job.out_dir / kCacheKeyFile);
  fs::remove(synth_job.out_dir / kJobMarkerFile);
}

}  // namespace varslam::report
