#include "eval/ate.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace varslam {

AteResult evaluate_ate(const Trajectory& gt, const Trajectory& est, const AteOptions& options) {
  const auto matches = associate_timestamps(gt, est, {options.offset, options.max_difference});
  if (matches.size() < 2) {
    throw InputError("ATE: only " + std::to_string(matches.size()) +
                     " estimate pose(s) lie within " + std::to_string(options.max_difference) +
                     " s of a ground-truth pose; are these files of the same sequence?");
  }
  const auto n = static_cast<Eigen::Index>(matches.size());
  Eigen::Matrix3Xd gt_xyz(3, n);
  Eigen::Matrix3Xd est_xyz(3, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto& m = matches[static_cast<std::size_t>(k)];
    gt_xyz.col(k) = gt[m.first].T_wc.translation();
    est_xyz.col(k) = est[m.second].T_wc.translation();
  }

  AteResult r;
  r.alignment = options.fixed_alignment ? *options.fixed_alignment : align_point_sets(est_xyz, gt_xyz, options.with_scale);
  std::vector<double> errors;
  errors.reserve(matches.size());
  r.pairs.reserve(matches.size());
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto& m = matches[static_cast<std::size_t>(k)];
    AtePair p;
    p.gt_timestamp = gt[m.first].timestamp;
    p.est_timestamp = est[m.second].timestamp;
    p.gt_position = gt_xyz.col(k);
    p.est_aligned_position = r.alignment.apply(Eigen::Vector3d(est_xyz.col(k)));
    p.error = (p.est_aligned_position - p.gt_position).norm();
    errors.push_back(p.error);
    r.pairs.push_back(p);
  }
  r.stats = compute_error_statistics(std::move(errors));

  r.aligned_estimate.reserve(est.size());
  for (const auto& sp : est) r.aligned_estimate.push_back({sp.timestamp, r.alignment.apply(sp.T_wc)});
  std::stable_sort(r.aligned_estimate.begin(), r.aligned_estimate.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.timestamp < b.timestamp; });
  return r;
}

double correct_rate(std::size_t pairs, std::size_t frame_count) {
  if (frame_count == 0) return 0.0;
  return std::min(1.0, static_cast<double>(pairs) / static_cast<double>(frame_count));
}

std::size_t count_frames_with_ground_truth(const std::vector<double>& frame_timestamps, const Trajectory& gt,
                                           double max_difference) {
  if (gt.empty()) return 0;
  std::vector<double> stamps;
  stamps.reserve(gt.size());
  for (const auto& p : gt) stamps.push_back(p.timestamp);
  std::sort(stamps.begin(), stamps.end());
  return static_cast<std::size_t>(std::count_if(frame_timestamps.begin(), frame_timestamps.end(), [&](double t) {
    return std::abs(stamps[nearest_timestamp_index(stamps, t)] - t) < max_difference;
  }));
}

}  // namespace varslam
