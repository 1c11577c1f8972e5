#pragma once
// `varslam bench` in a function: plan the matrix (bench_plan), run its jobs with the built-in executor
// (bench_local_executor: child processes of the same binary, in parallel up to the core count), then collect
// results.json, table.md, one report.html per run and index.html (bench_collect). The three steps are also
// separate commands, so that other executors (GNU parallel, xargs, Slurm) can run the same plan.
#include "report/bench_collect.hpp"
#include "report/bench_plan.hpp"
#include "report/bench_plan_file.hpp"

namespace varslam::report {

/// Runs the whole benchmark. Throws InputError on bad options (unknown scenario/config, missing path, ...);
/// failed runs do not throw: they are recorded and shown as "fail" in the table.
BenchOutcome run_benchmark(const BenchOptions& options);

}  // namespace varslam::report
