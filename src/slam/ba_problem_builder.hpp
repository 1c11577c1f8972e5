#pragma once
// Turns keyframes and map points into the plain optimiser problem (optim::BaProblem) and applies what the
// optimiser found back to the map; shared by Local BA and global BA.
#include <map>
#include <utility>
#include <vector>

#include "optim/local_ba.hpp"
#include "slam/keyframe.hpp"

namespace varslam::slam {

/// The observation of keypoint i of a keyframe or frame, as the optimisers take it.
optim::Observation keypoint_observation(const FrameFeatures& f, std::size_t i);

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
