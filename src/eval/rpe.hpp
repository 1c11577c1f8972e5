#pragma once
// Relative pose error like the TUM benchmark's evaluate_rpe with --fixed_delta --delta 1 --delta_unit s:
// for every estimate pose i, j is the estimate pose nearest to t_i + delta (pairs whose j is the last pose
// are dropped, as the tool does); both are matched to their nearest ground-truth poses, and pairs whose
// ground truth is further than twice the median ground-truth interval are skipped. The error of a pair is
// E = (Est_i^-1 Est_j)^-1 (Gt_i^-1 Gt_j); its translation norm and rotation angle are summarised.
// Two deliberate differences from the tool: all pairs are used (it samples 10000 at random when there are
// more), and a pose is never paired with itself (which the tool does before a gap longer than 2 delta).
#include <vector>

#include "core/trajectory.hpp"
#include "eval/error_statistics.hpp"

namespace varslam {

struct RpeOptions {
  double delta_seconds = 1.0;  // time between the two poses of a pair
  double offset = 0.0;         // seconds added to the estimate's timestamps
  double scale = 1.0;          // applied to the estimate's relative translations
};

struct RpePair {
  double est_t0 = 0.0, est_t1 = 0.0;
  double gt_t0 = 0.0, gt_t1 = 0.0;
  double translation_error = 0.0;  // metres
  double rotation_error_deg = 0.0;
};

struct RpeResult {
  ErrorStatistics translation;   // metres per delta
  ErrorStatistics rotation_deg;  // degrees per delta
  std::vector<RpePair> pairs;    // in estimate time order
};

/// Throws InputError when fewer than 2 pairs can be formed (as evaluate_rpe does).
RpeResult evaluate_rpe(const Trajectory& gt, const Trajectory& est, const RpeOptions& options = {});

}  // namespace varslam
