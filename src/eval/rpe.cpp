#include "eval/rpe.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "core/error.hpp"
#include "eval/association.hpp"

namespace varslam {
namespace {

Trajectory sorted_by_time(Trajectory t) {
  std::stable_sort(t.begin(), t.end(), [](const StampedPose& a, const StampedPose& b) { return a.timestamp < b.timestamp; });
  return t;
}

std::vector<double> stamps_of(const Trajectory& t) {
  std::vector<double> s;
  s.reserve(t.size());
  for (const auto& p : t) s.push_back(p.timestamp);
  return s;
}

double median_interval(const std::vector<double>& sorted) {
  std::vector<double> d;
  for (std::size_t k = 1; k < sorted.size(); ++k) d.push_back(sorted[k] - sorted[k - 1]);
  std::sort(d.begin(), d.end());
  const std::size_t mid = d.size() / 2;
  return d.size() % 2 == 1 ? d[mid] : 0.5 * (d[mid - 1] + d[mid]);
}

// Rotation angle from the trace, clamped like the tool's compute_angle (round-off can leave |cos| > 1).
double angle_of(const Eigen::Matrix3d& R) {
  return std::acos(std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0));
}

}  // namespace

RpeResult evaluate_rpe(const Trajectory& gt_in, const Trajectory& est_in, const RpeOptions& options) {
  const Trajectory gt = sorted_by_time(gt_in);
  const Trajectory est = sorted_by_time(est_in);
  if (gt.size() < 2 || est.size() < 2) {
    throw InputError("RPE: need at least 2 poses in both trajectories (ground truth " + std::to_string(gt.size()) +
                     ", estimate " + std::to_string(est.size()) + ")");
  }
  const auto gt_stamps = stamps_of(gt);
  const auto est_stamps = stamps_of(est);
  // No pose has a partner delta later: say so, rather than suggest files of different sequences.
  if (const double span = est_stamps.back() - est_stamps.front(); span < options.delta_seconds)
    throw InputError(fmt::format("RPE: the run is too short for RPE at a delta of {:g} s: its poses span {:.2f} s",
                                 options.delta_seconds, span));
  const double max_gt_gap = 2.0 * median_interval(gt_stamps);

  RpeResult r;
  std::vector<double> trans;
  std::vector<double> rot;
  for (std::size_t i = 0; i < est.size(); ++i) {
    const std::size_t j = nearest_timestamp_index(est_stamps, est_stamps[i] + options.delta_seconds);
    if (j == est.size() - 1) continue;  // evaluate_rpe drops these (including genuine ones at the end)
    // Before a tracking gap longer than 2 delta, the nearest pose to t_i + delta is i itself: a zero-length
    // "pair" with zero error that evaluate_rpe keeps; it only dilutes the statistics, so it is skipped.
    if (j == i) continue;
    const double t0 = est_stamps[i] + options.offset;
    const double t1 = est_stamps[j] + options.offset;
    const std::size_t g0 = nearest_timestamp_index(gt_stamps, t0);
    const std::size_t g1 = nearest_timestamp_index(gt_stamps, t1);
    if (std::abs(gt_stamps[g0] - t0) > max_gt_gap || std::abs(gt_stamps[g1] - t1) > max_gt_gap) continue;

    Eigen::Isometry3d est_rel = est[j].T_wc.inverse() * est[i].T_wc;  // the tool's ominus(est_j, est_i)
    est_rel.translation() *= options.scale;
    const Eigen::Isometry3d gt_rel = gt[g1].T_wc.inverse() * gt[g0].T_wc;
    const Eigen::Isometry3d error = est_rel.inverse() * gt_rel;

    RpePair p;
    p.est_t0 = est_stamps[i];
    p.est_t1 = est_stamps[j];
    p.gt_t0 = gt_stamps[g0];
    p.gt_t1 = gt_stamps[g1];
    p.translation_error = error.translation().norm();
    p.rotation_error_deg = angle_of(error.linear()) * 180.0 / std::numbers::pi;
    trans.push_back(p.translation_error);
    rot.push_back(p.rotation_error_deg);
    r.pairs.push_back(p);
  }
  if (r.pairs.size() < 2) {
    throw InputError("RPE: only " + std::to_string(r.pairs.size()) + " pose pair(s) " +
                     std::to_string(options.delta_seconds) +
                     " s apart match the ground truth; are these files of the same sequence?");
  }
  r.translation = compute_error_statistics(std::move(trans));
  r.rotation_deg = compute_error_statistics(std::move(rot));
  return r;
}

}  // namespace varslam
