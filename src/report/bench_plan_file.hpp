#pragma once
// The benchmark plan as a file: <out>/plan.jsonl, a header line and one line per job (docs/bench_plan.md). Any
// executor reads it; a reader refuses another format version.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "io/output_folder.hpp"
#include "report/bench_plan.hpp"

namespace varslam::report {

/// The plan file's format name and version; a reader refuses any other version.
inline constexpr const char* kBenchPlanFormat = "varslam bench plan";
inline constexpr int kBenchPlanVersion = 1;

/// Claims the plan folder for the benchmark's own files (plan.jsonl, results.json, table.md, index.html) before
/// anything else is checked: a folder holding the user's files of those names is refused (InputError naming them),
/// and a second benchmark into it is refused while the returned folder is held.
std::unique_ptr<OutputFolder> claim_bench_folder(const std::filesystem::path& out);

/// Removes the outputs and completion markers of earlier runs into the plan's run folders, invalidates the plan's
/// cached sequences when `fresh_sequences`, and writes plan.jsonl (into a folder claim_bench_folder claimed).
void write_bench_plan(const BenchPlan& plan, bool fresh_sequences);

/// Reads <dir>/plan.jsonl; InputError naming the folder, file, line or key on anything wrong (no folder, no plan,
/// another format version, a missing key, jobs out of order, a dependency on a later job).
BenchPlan read_bench_plan(const std::filesystem::path& dir);

nlohmann::json to_json(const PlanJob& job);
/// The job as its plan line: the keys in the order docs/bench_plan.md lists them.
nlohmann::ordered_json job_line(const PlanJob& job);
nlohmann::json to_json(const SequenceSpec& seq);

}  // namespace varslam::report
