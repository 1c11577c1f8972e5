#pragma once
// Helpers shared by the subcommands: settings overrides from the command line, summary printing.
#include <string>
#include <vector>

#include "io/settings.hpp"
#include "io/settings_registry.hpp"
#include "run/dataset_run.hpp"

namespace varslam::cli {

/// Writes <run>/report.html (plots of the trajectory, error, alpha per keyframe, timings); a failure is a warning.
void write_report_for_run(const std::filesystem::path& run_dir, const std::filesystem::path& sequence_dir);

/// One human-readable block: frames, tracking share, keyframes, speed, ATE, and where the files went.
void print_run_summary(const run::RunSummary& s);

}  // namespace varslam::cli
