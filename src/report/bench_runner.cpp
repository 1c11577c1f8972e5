#include "report/bench_runner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

#include "report/bench_local_executor.hpp"
#include "report/machine_info.hpp"

namespace varslam::report {

BenchOutcome run_benchmark(const BenchOptions& options) {
  const auto log = [&options](const std::string& line) {
    if (options.log) options.log(line);
    else fmt::print("{}\n", line);
  };
  const auto t_start = std::chrono::steady_clock::now();
  const auto elapsed = [t_start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  };
  BenchOptions o = options;
  o.jobs = o.jobs ? o.jobs : std::max(1u, sample_machine_info().cores);  // recorded in the plan's options
  const auto folder = claim_bench_folder(o.out);  // held until the tables are written
  const BenchPlan plan = make_bench_plan(o);
  write_bench_plan(plan, !o.reuse_sequences);
  execute_plan_locally(plan, o.jobs, log, elapsed);
  CollectOptions c;
  c.update_markdown = o.update_markdown;
  c.wall_seconds = elapsed();
  c.log = log;
  return collect_benchmark(plan, c);
}

}  // namespace varslam::report
