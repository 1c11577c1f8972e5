#pragma once
// Absolute trajectory error exactly as the TUM benchmark's evaluate_ate computes it: associate estimate
// and ground truth by timestamp, align the associated estimate positions onto the ground truth (rigid by
// default, Sim(3) on request), then summarise the per-pair translational error.
#include <cstddef>
#include <optional>
#include <vector>

#include "core/trajectory.hpp"
#include "eval/alignment.hpp"
#include "eval/association.hpp"
#include "eval/error_statistics.hpp"

namespace varslam {

struct AteOptions {
  double max_difference = 0.02;  // seconds, association window (strict)
  double offset = 0.0;           // seconds added to the estimate's timestamps
  bool with_scale = false;       // Sim(3) alignment for monocular estimates
  /// Evaluate through this alignment instead of fitting one: a localization run in a saved map is measured in the
  /// map's own alignment to ground truth, so a run that sits consistently offset shows its offset.
  std::optional<Alignment> fixed_alignment;
};

struct AtePair {
  double gt_timestamp = 0.0;
  double est_timestamp = 0.0;
  Eigen::Vector3d gt_position = Eigen::Vector3d::Zero();
  Eigen::Vector3d est_aligned_position = Eigen::Vector3d::Zero();
  double error = 0.0;  // metres, |aligned estimate - ground truth|
};

struct AteResult {
  ErrorStatistics stats;             // stats.count = number of associated pairs
  Alignment alignment;               // maps estimate coordinates into the ground-truth frame
  std::vector<AtePair> pairs;        // sorted by ground-truth time
  Trajectory aligned_estimate;       // every estimate pose (matched or not) in the ground-truth frame
};

/// Throws InputError when fewer than 2 poses associate (as evaluate_ate refuses to run).
AteResult evaluate_ate(const Trajectory& gt, const Trajectory& est, const AteOptions& options = {});

/// Correct rate: associated pairs / frame_count, where frame_count is what the caller counts as "should
/// have a pose" (the number of input frames covered by ground truth, see count_frames_with_ground_truth;
/// or, lacking that, the number of estimate poses). 0 when frame_count is 0; capped at 1.
double correct_rate(std::size_t pairs, std::size_t frame_count);

/// How many frame timestamps have a ground-truth pose within max_difference (strict), i.e. the frames an
/// evaluation could possibly count: the denominator of the correct rate.
std::size_t count_frames_with_ground_truth(const std::vector<double>& frame_timestamps, const Trajectory& gt,
                                           double max_difference = 0.02);

}  // namespace varslam
