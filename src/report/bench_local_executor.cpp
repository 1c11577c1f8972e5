#include "report/bench_local_executor.hpp"

#include <fmt/format.h>

#include <cmath>
#include <map>

#include "report/bench_collect.hpp"
#include "report/bench_job.hpp"
#include "report/process_pool.hpp"

namespace varslam::report {
namespace fs = std::filesystem;
namespace {

// "run <sequence> <config>  ATE 0.41 cm" for the progress line.
std::string what_ended(const BenchPlan& plan, const PlanJob& job, const JobMarker& marker) {
  if (job.kind == PlanJob::Kind::Synth) return fmt::format("synth {}", job.sequence);
  nlohmann::json metrics;
  const RunRecord r = record_of_job(plan, job, marker, metrics);
  std::string what = fmt::format("{} {} {}", job.kind == PlanJob::Kind::Peer ? plan.peer_name : "run", job.sequence,
                                 job.config);
  if (r.ok && std::isfinite(r.figures.ate_rmse_m)) what += fmt::format("  ATE {:.2f} cm", 100.0 * r.figures.ate_rmse_m);
  return what;
}

}  // namespace

LocalExecution execute_plan_locally(const BenchPlan& plan, std::size_t parallel,
                                    const std::function<void(const std::string&)>& log,
                                    const std::function<double()>& elapsed) {
  std::vector<std::size_t> todo;           // job numbers, in plan order
  std::map<std::size_t, std::size_t> task_of;  // job number -> task index
  std::size_t to_generate = 0, cached = 0;
  for (const auto& job : plan.jobs) {
    const bool complete = job_state(plan, job) == JobState::Complete;
    if (job.kind == PlanJob::Kind::Synth) ++(complete ? cached : to_generate);
    if (complete) continue;
    task_of[job.number] = todo.size();
    todo.push_back(job.number);
  }
  std::vector<ProcessTask> tasks;
  for (const std::size_t n : todo) {
    const PlanJob& job = plan.jobs[n];
    ProcessTask t;
    t.argv = {plan.executable.string(), "bench", "run-job", plan.dir.string(), std::to_string(n)};
    t.log_file = plan.dir / "jobs" / fmt::format("{}.log", n);
    for (const std::size_t need : job.needs)
      if (task_of.count(need)) t.after.push_back(task_of[need]);  // complete needs are no dependency
    tasks.push_back(std::move(t));
  }
  if (!tasks.empty()) fs::create_directories(plan.dir / "jobs");
  log(fmt::format("bench: {} sequences ({} to generate, {} cached), {} configurations, {} child processes, {} at a "
                  "time -> {}",
                  plan.sequences.size(), to_generate, cached, plan.configs.size(), tasks.size(), parallel,
                  plan.dir.string()));

  LocalExecution result;
  result.started = tasks.size();
  const auto progress = [&](std::size_t i, const ProcessOutcome& outcome, std::size_t done) {
    const PlanJob& job = plan.jobs[todo[i]];
    const bool skipped = outcome.state == ProcessOutcome::State::Skipped;
    auto marker = read_job_marker(job);
    const bool recorded = marker && marker->plan_id == plan.id && marker->job == job.number;
    if (skipped) {
      marker = record_failed_job(plan, job, kSkippedError);
    } else if (!recorded) {
      // run-job itself failed before it could record the job (a bad plan, a crash): say so where collect looks.
      marker = record_failed_job(plan, job, fmt::format("varslam bench run-job: {}, log {}", outcome.error,
                                                        tasks[i].log_file.string()));
    }
    const bool ok = marker->ok;
    result.failed += !ok;
    const char* state = ok ? "ok" : (skipped ? "SKIPPED" : "FAILED");
    log(fmt::format("[{}/{}] {:>6.0f} s  {} {} ({:.1f} s){}", done, tasks.size(), elapsed(),
                    what_ended(plan, job, *marker), state, marker->wall_seconds,
                    ok ? "" : "  " + marker->error + ", log " + job.log_file.string()));
  };
  run_processes(tasks, parallel, progress);
  return result;
}

}  // namespace varslam::report
