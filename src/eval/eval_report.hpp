#pragma once
// One call from trajectories to everything a report needs: ATE, RPE, correct rate, a printable table,
// JSON with every number, and the standard plots (top view, ATE error over time).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/trajectory.hpp"
#include "eval/ate.hpp"
#include "eval/rpe.hpp"
#include "eval/svg_plot.hpp"

namespace varslam {

struct EvalOptions {
  AteOptions ate;
  double rpe_delta_seconds = 1.0;
  /// Denominator of the correct rate (frames that should have a pose). Unset: the number of estimate poses.
  std::optional<std::size_t> frame_count;
};

struct EvalSummary {
  AteResult ate;
  std::optional<RpeResult> rpe;  // unset when no pose pairs delta apart match (short or gappy estimates)
  std::string rpe_unavailable;   // why, when rpe is unset
  std::size_t gt_poses = 0;
  std::size_t est_poses = 0;
  std::size_t frame_count = 0;    // the correct-rate denominator actually used
  bool frame_count_given = false;  // false: frame_count is the number of estimate poses
  double correct_rate = 0.0;       // ate pairs / frame_count
  EvalOptions options;
};

/// Throws InputError when ATE cannot be computed (fewer than 2 associated poses).
EvalSummary evaluate_trajectory(const Trajectory& gt, const Trajectory& est, const EvalOptions& options = {});

/// Human-readable table of every figure (several lines, ends with a newline).
std::string format_eval_table(const EvalSummary& summary);

/// Every figure; with per_pair, also the ATE error of each pair (for external plotting).
nlohmann::json eval_to_json(const EvalSummary& summary, bool per_pair = false);

/// Indices (ascending) of the two coordinate axes along which the ground truth spreads most.
std::pair<int, int> top_view_axes(const Trajectory& gt);
/// Ground truth and aligned estimate seen along the axis of least spread, equal aspect.
Plot trajectory_top_view_plot(const Trajectory& gt, const AteResult& ate);
/// ATE error of each pair over time (seconds from the first pair), with the RMSE as a reference line.
Plot ate_error_plot(const AteResult& ate);

/// Writes the top view to `file` and the error plot next to it as <stem>_ate_error<ext> (.svg or .png).
/// Returns the paths written.
std::vector<std::filesystem::path> write_eval_plots(const Trajectory& gt, const EvalSummary& summary,
                                                    const std::filesystem::path& file);

}  // namespace varslam
