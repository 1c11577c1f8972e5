#pragma once
// `varslam bench collect`: the tables, results.json, index.html and the BENCHMARKS.md block of a plan, from
// whichever of its jobs have ended; the missing ones are named (and left out of the tables).
#include <cstddef>
#include <filesystem>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "report/bench_job.hpp"
#include "report/bench_plan.hpp"
#include "report/bench_results.hpp"

namespace varslam::report {

struct CollectOptions {
  std::filesystem::path update_markdown;        // BENCHMARKS.md to rewrite between its markers; empty = none
  double wall_seconds = std::numeric_limits<double>::quiet_NaN();  // the benchmark's; NaN = since it was planned
  std::function<void(const std::string&)> log;  // empty = stdout
};

struct BenchOutcome {
  std::filesystem::path out;
  std::size_t runs = 0, failed = 0;
  std::vector<std::size_t> missing;  // job numbers that have not ended
  double wall_seconds = 0.0;
  std::string table_markdown;
  nlohmann::json results;
};

/// The table record of a run or peer job that ended (its marker and outputs). `metrics` receives the run's
/// metrics.json (null when there is none).
RunRecord record_of_job(const BenchPlan& plan, const PlanJob& job, const JobMarker& marker, nlohmann::json& metrics);

/// Writes results.json, table.md and index.html into the plan folder (and the Markdown block when asked) from the
/// jobs that ended; returns what it wrote and which jobs are missing.
BenchOutcome collect_benchmark(const BenchPlan& plan, const CollectOptions& options);

}  // namespace varslam::report
