#pragma once
// The built-in executor of a benchmark plan: every job that is not complete runs as a `varslam bench run-job DIR N`
// child process of the plan's binary, at most N at a time, each after the jobs it needs (process_pool). It is one
// executor among others (GNU parallel, xargs, Slurm): it runs exactly what they would run.
#include <cstddef>
#include <functional>
#include <string>

#include "report/bench_plan.hpp"

namespace varslam::report {

struct LocalExecution {
  std::size_t started = 0;  // run-job processes
  std::size_t failed = 0;   // jobs that ended badly or were skipped
};

/// Runs the plan's incomplete jobs (failed ones again), `parallel` at a time, and logs one line per finished job
/// (what it was, ok / FAILED / SKIPPED, its time, and the ATE of a run). `elapsed` gives the seconds shown.
LocalExecution execute_plan_locally(const BenchPlan& plan, std::size_t parallel,
                                    const std::function<void(const std::string&)>& log,
                                    const std::function<double()>& elapsed);

}  // namespace varslam::report
