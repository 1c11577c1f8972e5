#pragma once
// Turns map data into the plain optimiser problems: a frame's matches into a pose-only problem (tracking,
// relocalization, loop verification), keyframes and points into optim::BaProblem (Local and global BA), and
// applies what bundle adjustment found back to the map.
#include <map>
#include <utility>
#include <vector>

#include "optim/local_ba.hpp"
#include "slam/keyframe.hpp"

namespace varslam::slam {

/// The observation of keypoint i of a keyframe or frame, as the optimisers take it.
optim::Observation keypoint_observation(const FrameFeatures& f, std::size_t i);

/// A frame's matches as a pose-only problem: every matched map point, its observation, and the keypoint index.
struct FramePoseProblem {
  std::vector<Eigen::Vector3d> points;
  std::vector<optim::Observation> observations;
  std::vector<int> keypoints;
};
FramePoseProblem frame_pose_problem(const Frame& f);

struct BaProblemBuilder {
  optim::BaProblem problem;
  std::vector<KeyFramePtr> keyframes;  // index = problem keyframe index
  std::vector<MapPointPtr> points;     // index = problem point index
  std::vector<std::pair<KeyFramePtr, MapPointPtr>> observation_owner;  // index = problem observation index

  void add_keyframe(const KeyFramePtr& kf, bool fixed);
  /// Adds the point with its observations in keyframes already added (not bad); false (nothing added) when
  /// none of its observers is in the problem.
  bool add_point(const MapPointPtr& mp);

  /// Writes the optimised poses (non-fixed keyframes) and point positions back. Call under the map's update lock.
  void write_back() const;
  /// Detaches the observations the optimiser flagged as outliers; returns how many.
  int erase_outliers(const std::vector<bool>& outlier_observation) const;

 private:
  std::map<long, int> index_of_;
};

}  // namespace varslam::slam
