#pragma once
// Locating a frame against one keyframe with no pose prior (relocalization, loop verification): descriptor
// matches to the keyframe's map points, a rigid 3-D/3-D RANSAC on the keypoints that have depth (RGB-D gives
// metric points, so three matches fix a pose), then pose-only optimisation on all matches.
#include <optional>

#include "optim/kernel.hpp"
#include "slam/frame.hpp"
#include "slam/keyframe.hpp"

namespace varslam::slam {

struct LocalizationConfig {
  int min_matches = 20;          // descriptor matches needed to try RANSAC
  int min_inliers = 20;          // after RANSAC and after pose optimisation
  int ransac_iterations = 200;
  // Depth noise grows with the square of depth: a match is a RANSAC inlier within base + per_m2 * z^2 metres.
  double tolerance_base = 0.02, tolerance_per_m2 = 0.01;
  double tolerance(double z) const { return tolerance_base + tolerance_per_m2 * z * z; }
  optim::KernelConfig kernel;  // pose refinement
};

/// On success sets cur.T_cw and cur.map_points (inliers only, outlier flags cleared) and returns the number of
/// inliers; otherwise clears cur.map_points, leaves cur.T_cw as it was and returns 0.
int locate_against_keyframe(Frame& cur, const KeyFrame& kf, const LocalizationConfig& cfg);

/// A keyframe and its best covisible keyframes, with their map points (each once, in keyframe order).
struct KeyframeNeighbourhood {
  std::vector<long> keyframe_ids;
  std::vector<MapPointPtr> points;
};
KeyframeNeighbourhood keyframe_neighbourhood(const KeyFrame& kf, int covisibles);

/// The same against the map points of a keyframe's neighbourhood (`points`, e.g. the keyframe's and its best
/// covisibles'): a frame between mapped viewpoints sees a place that no single keyframe sees enough of.
/// `seed` makes the RANSAC deterministic.
int locate_against_points(Frame& cur, const std::vector<MapPointPtr>& points, std::uint64_t seed,
                          const LocalizationConfig& cfg);

/// Metric points in one camera's coordinates (from keypoints with depth, possibly of several frames), each with its
/// descriptor (one row each) and measured depth.
struct CameraPoints {
  std::vector<Eigen::Vector3d> p_c;
  std::vector<double> depth;
  cv::Mat descriptors;
};

/// The camera's pose T_cw from descriptor matches of `camera` to `points` (each map point once) and a rigid RANSAC
/// on their 3-D positions (cfg.min_inliers, cfg.ransac_iterations, the depth tolerance); empty when none is found.
std::optional<Eigen::Isometry3d> locate_points_by_depth(const CameraPoints& camera,
                                                        const std::vector<MapPointPtr>& points, std::uint64_t seed,
                                                        const LocalizationConfig& cfg);

/// Pose-only optimisation of cur.T_cw on its current matches (outliers dropped from cur.map_points); returns the
/// inliers. Shared by relocalization and loop verification.
int refine_pose_on_matches(Frame& cur, const optim::KernelConfig& kernel);

}  // namespace varslam::slam
