#pragma once
// A single self-contained HTML page for one SLAM run: key numbers, trajectory top view against ground truth,
// ATE error over time, the adaptive kernel's alpha per keyframe (the paper's Fig. 6/8), per-stage timing bars
// and the sequence's preview image (embedded as a data URI, so the file can be mailed or archived alone).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "core/trajectory.hpp"
#include "eval/svg_plot.hpp"

namespace varslam::report {

/// Everything a run report shows, loaded from a run folder (and its input sequence).
struct RunReportInputs {
  std::string title;                         // usually the run folder's name
  nlohmann::json metrics;                    // the run's metrics.json
  Trajectory estimate;                       // CameraTrajectory.txt (empty when missing)
  Trajectory groundtruth;                    // the sequence's groundtruth.txt (empty when none)
  std::optional<std::string> preview_uri;    // data URI of the sequence's preview.png
  nlohmann::json scenario;                   // the sequence's scenario.json (null for real data)
  std::filesystem::path run_dir, sequence_dir;
};

/// Reads run_dir/metrics.json (required: InputError naming the file when missing or malformed) and, where they
/// exist, CameraTrajectory.txt, the ground truth, preview.png and scenario.json. An empty sequence_dir means
/// the dataset folder recorded in metrics.json.
RunReportInputs load_run_report_inputs(const std::filesystem::path& run_dir,
                                       const std::filesystem::path& sequence_dir = {});

/// The report page as one HTML string.
std::string render_run_report(const RunReportInputs& inputs);

/// load + render + write; throws InputError when the run cannot be read or the file not written.
void write_run_report(const std::filesystem::path& run_dir, const std::filesystem::path& sequence_dir,
                      const std::filesystem::path& out_html);

/// Final alpha of each local BA over time (seconds since t0); empty plot series when no alpha was estimated.
Plot alpha_per_keyframe_plot(const nlohmann::json& metrics, double t0);
/// Median and 95th percentile per pipeline stage, as grouped bars (milliseconds).
Plot stage_timing_plot(const nlohmann::json& metrics);

/// metrics[a][b]... as a double; NaN when any key is missing or the value is not a number.
double json_number(const nlohmann::json& j, std::initializer_list<const char*> keys);

}  // namespace varslam::report
