#include "slam/near_mover.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "optim/kernel.hpp"

namespace varslam::slam {

bool split_by_depth(const std::vector<double>& depths, double& near_centre, double& far_centre, double& boundary) {
  std::vector<double> l;
  l.reserve(depths.size());
  for (double z : depths)
    if (z > 0) l.push_back(std::log(z));
  if (l.size() < 2) return false;
  std::sort(l.begin(), l.end());
  if (l.front() == l.back()) return false;
  // Start from the quartiles; a few Lloyd steps converge on sorted 1-D data.
  double a = l[l.size() / 4], b = l[(3 * l.size()) / 4];
  if (a == b) {
    a = l.front();
    b = l.back();
  }
  for (int it = 0; it < 10; ++it) {
    const double mid = 0.5 * (a + b);
    double sa = 0, sb = 0;
    std::size_t na = 0, nb = 0;
    for (double v : l) {
      if (v < mid) {
        sa += v;
        ++na;
      } else {
        sb += v;
        ++nb;
      }
    }
    if (na == 0 || nb == 0) break;
    const double a2 = sa / static_cast<double>(na), b2 = sb / static_cast<double>(nb);
    if (a2 == a && b2 == b) break;
    a = a2;
    b = b2;
  }
  near_centre = std::exp(a);
  far_centre = std::exp(b);
  boundary = std::exp(0.5 * (a + b));
  return true;
}

namespace {

// Chi-square of the observation at T_cw over its gate (> 1: the plain gate rejects it); infinite behind the camera.
double gated_chi2(const PinholeCamera& cam, const Eigen::Isometry3d& T_cw, const Eigen::Vector3d& p_w,
                  const optim::Observation& o) {
  const Eigen::Vector3d p_c = T_cw * p_w;
  if (p_c.z() <= 0) return std::numeric_limits<double>::infinity();
  int dof = 0;
  const double chi2 = optim::whitened_chi2(cam, o, p_c, dof);
  return chi2 / optim::chi2_threshold(dof);
}

}  // namespace

NearMoverVerdict check_near_mover(const PinholeCamera& cam, const Eigen::Isometry3d& T_cw,
                                  const std::vector<Eigen::Vector3d>& points_w,
                                  const std::vector<optim::Observation>& obs, const optim::PoseOptimConfig& pose,
                                  const NearMoverConfig& cfg) {
  NearMoverVerdict v;
  std::vector<double> depth(points_w.size());
  for (std::size_t k = 0; k < points_w.size(); ++k) depth[k] = (T_cw * points_w[k]).z();
  if (!split_by_depth(depth, v.near_depth, v.far_depth, v.split_depth)) return v;
  if (v.far_depth < cfg.min_depth_ratio * v.near_depth) return v;
  std::vector<Eigen::Vector3d> far_points;
  std::vector<optim::Observation> far_obs;
  std::vector<std::size_t> near_idx;
  for (std::size_t k = 0; k < points_w.size(); ++k) {
    if (depth[k] <= 0) continue;
    if (depth[k] < v.split_depth) {
      near_idx.push_back(k);
    } else {
      far_points.push_back(points_w[k]);
      far_obs.push_back(obs[k]);
    }
  }
  v.near = static_cast<int>(near_idx.size());
  v.far = static_cast<int>(far_points.size());
  if (v.near < cfg.min_points || v.far < cfg.min_points) return v;
  v.T_far = T_cw;
  const optim::PoseOptimResult far = optim::optimize_pose(cam, v.T_far, far_points, far_obs, pose);
  v.far_inliers = far.inliers;
  // The far cluster must itself be one rigid motion, or it cannot speak for the room.
  if (far.inliers < cfg.min_points || far.inliers < v.far / 2) return v;
  v.split = true;
  v.mover.assign(points_w.size(), false);
  std::vector<double> near_chi2;
  for (std::size_t k : near_idx) {
    near_chi2.push_back(gated_chi2(cam, v.T_far, points_w[k], obs[k]));
    if (near_chi2.back() > cfg.gate_factor) {
      v.mover[k] = true;
      ++v.moving_points;
    }
  }
  std::nth_element(near_chi2.begin(), near_chi2.begin() + static_cast<std::ptrdiff_t>(near_chi2.size() / 2), near_chi2.end());
  v.near_median_chi2 = near_chi2[near_chi2.size() / 2];
  v.moving = v.moving_points >= cfg.min_moving && v.moving_points >= cfg.min_moving_share * v.near &&
             v.near_median_chi2 >= cfg.min_median_chi2;
  if (!v.moving) v.mover.clear();
  return v;
}

}  // namespace varslam::slam
