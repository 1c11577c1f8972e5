#pragma once
// Matching by projection: map points are projected with a predicted pose and matched to keypoints near
// the projection by descriptor distance (the SLAM-specific searches; plain descriptor tools live in features/).
#include <Eigen/Geometry>
#include <vector>

#include "slam/frame.hpp"
#include "slam/keyframe.hpp"

namespace varslam::slam {

inline constexpr int kDescDistHigh = 100;  // loosest accepted Hamming distance (of 256 bits)
inline constexpr int kDescDistLow = 50;    // strict distance for fusing and triangulation
inline constexpr double kNeighbourhoodMatchRatio = 0.9;  // ratio test for points seen from other viewpoints

/// Matches the map points of `last` into `cur` (whose T_cw holds the prediction). `radius` in pixels at level
/// 0, scaled by the keypoint's level. Returns the number of new matches.
int match_last_frame(Frame& cur, const Frame& last, double radius);

/// Who projects local map points: tracking (its thread owns the points' per-frame scratch and their visibility
/// counts) or a check on another thread, like loop verification, which must read and touch neither.
enum class LocalMapUse { Tracking, Verification };

/// Projects local map points into `cur` (frustum and viewing-angle checks, scale prediction) and matches the
/// ones not matched yet. For tracking, skips points already matched in this frame (MapPoint::last_seen_frame)
/// and marks visited points visible. `radius_scale` widens the search (e.g. after a loss).
int match_local_map(Frame& cur, const std::vector<MapPointPtr>& points, double radius_scale,
                    LocalMapUse use = LocalMapUse::Tracking);

/// Descriptor matching of the keyframe's map points against all of the frame's keypoints (ratio test,
/// rotation consistency); the fallback when the motion model fails.
int match_keyframe_by_descriptor(Frame& cur, const KeyFrame& kf);

/// The points of `points` that have a descriptor and are not bad, with their descriptors as the rows of one matrix
/// (the query or train side of a brute-force descriptor matching).
struct PointDescriptors {
  std::vector<MapPointPtr> points;
  cv::Mat rows;
};
PointDescriptors point_descriptors(const std::vector<MapPointPtr>& points);

/// Descriptor matching of map points (their representative descriptors) against all of the frame's keypoints
/// (ratio test, one point per keypoint), with no pose prior: a place seen from several keyframes at once.
int match_points_by_descriptor(Frame& cur, const std::vector<MapPointPtr>& points);

/// Projects `points` into `kf` and either adds them as new observations or fuses them with the point
/// already there (the one with more observations survives). Returns the number fused or added.
int fuse_into_keyframe(const KeyFramePtr& kf, const std::vector<MapPointPtr>& points, double radius = 3.0);

/// Pairs of unmatched keypoints (idx1 in kf1, idx2 in kf2) that agree in descriptor and epipolar geometry.
std::vector<std::pair<int, int>> match_for_triangulation(const KeyFrame& kf1, const KeyFrame& kf2);

}  // namespace varslam::slam
