#pragma once
// Large movers close to the camera: does the near part of a frame's matches move against the far part?
// The matches are split by depth into a near and a far cluster (two-means on log depth). When the two are clearly
// apart, the pose is solved on the far cluster alone and the near matches are tested at that pose: if many of
// them do not fit it, the near cluster is a mover (something carried in front of the lens) and the far cluster,
// the room behind it, gives the pose. Depth ordering decides, not the count: a mover covering most of the image
// has more matches than the background it hides, but it is always in front of it. A near cluster that fits the
// far pose (a desk in front of a wall, a box held still) is static and kept.
#include <Eigen/Geometry>
#include <vector>

#include "core/camera.hpp"
#include "optim/pose_optimizer.hpp"
#include "optim/reprojection.hpp"

namespace varslam::slam {

struct NearMoverConfig {
  double min_depth_ratio = 1.6;   // far cluster's typical depth over the near one's
  int min_points = 30;            // matches each cluster needs
  double min_moving_share = 0.3;  // share of near matches that must not fit the far pose
  int min_moving = 20;            // ... and at least this many
  // A near match "does not fit" the far pose beyond this multiple of the chi-square gate: the far cluster alone
  // pins the translation less well, and static near points then miss the plain gate by a few pixels.
  double gate_factor = 4.0;
  // ... and the near cluster as a whole misses it: its median chi-square is this many gates (static near points in
  // the real kitchen: median 3, 90th percentile 4; a carried box: median 14).
  double min_median_chi2 = 6.0;
};

struct NearMoverVerdict {
  bool split = false;   // two depth clusters far enough apart were found and tested
  bool moving = false;  // the near cluster moves against the far one
  Eigen::Isometry3d T_far = Eigen::Isometry3d::Identity();  // pose solved on the far cluster (split only)
  std::vector<bool> mover;  // per observation: near and not fitting T_far (moving only)
  int near = 0, far = 0, far_inliers = 0, moving_points = 0;
  double near_median_chi2 = 0;  // median near chi-square at T_far, over the plain gate
  double near_depth = 0, far_depth = 0, split_depth = 0;  // metres: cluster centres and the boundary
};

/// Tests the matches (points_w[k] observed as obs[k]) of a frame solved at T_cw. pose: how to solve the far
/// cluster's pose (the tracking settings).
NearMoverVerdict check_near_mover(const PinholeCamera& cam, const Eigen::Isometry3d& T_cw,
                                  const std::vector<Eigen::Vector3d>& points_w,
                                  const std::vector<optim::Observation>& obs, const optim::PoseOptimConfig& pose,
                                  const NearMoverConfig& cfg);

/// Two-means on log depth: the boundary between the near and the far cluster and the two centres (metres); false
/// when there are fewer than two distinct depths. Exposed for tests.
bool split_by_depth(const std::vector<double>& depths, double& near_centre, double& far_centre, double& boundary);

}  // namespace varslam::slam
