#pragma once
// Rolling-shutter compensation of a frame's keypoints: a rolling-shutter colour camera exposes its rows one after
// the other, so while the camera moves each row sees the scene from a slightly different pose. Each keypoint is
// moved to where the camera would have seen it at the instant of the middle row, the frame's own instant, using
// the motion model's velocity.
#include <Eigen/Geometry>
#include <vector>

#include "slam/frame.hpp"

namespace varslam::slam {

struct RollingShutter {
  double readout_s = 0;  // time from the first row's exposure to the last's; 0 = global shutter
  int rows = 0;          // image height: a row's instant is readout_s * (row / rows - 1/2) from the frame's
};

/// Moves the keypoints of `f` (and their depths and virtual right coordinates) to the middle row's instant.
/// `sensor_rows[i]` is keypoint i's row on the sensor (before undistortion). `motion` is the camera motion
/// T_cw(t + dt) * T_cw(t)^-1 over `dt` seconds (the motion model), assumed constant through the frame. A keypoint
/// with depth is moved as the 3-D point it measures; one without depth by the rotation alone (a far point).
/// Rebuilds the keypoint grid.
void compensate_rolling_shutter(FrameFeatures& f, const std::vector<float>& sensor_rows, const RollingShutter& shutter,
                                const Eigen::Isometry3d& motion, double dt);

}  // namespace varslam::slam
