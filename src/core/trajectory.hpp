#pragma once
// A camera trajectory: camera-to-world poses with timestamps (the TUM convention).
#include <Eigen/Geometry>
#include <vector>

namespace varslam {

struct StampedPose {
  double timestamp = 0.0;
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();  // camera-to-world
};

using Trajectory = std::vector<StampedPose>;

}  // namespace varslam
