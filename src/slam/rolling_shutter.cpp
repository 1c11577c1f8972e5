#include "slam/rolling_shutter.hpp"

#include <stdexcept>

#include "core/geometry.hpp"

namespace varslam::slam {

void compensate_rolling_shutter(FrameFeatures& f, const std::vector<float>& sensor_rows, const RollingShutter& shutter,
                                const Eigen::Isometry3d& motion, double dt) {
  if (sensor_rows.size() != f.size())
    throw std::invalid_argument("compensate_rolling_shutter: one sensor row per keypoint expected");
  if (shutter.readout_s <= 0 || shutter.rows <= 0 || dt <= 0 || f.size() == 0) return;
  const Eigen::Vector3d rotation = so3_log(motion.rotation());
  const Eigen::Vector3d translation = motion.translation();
  const PinholeCamera& cam = f.camera;
  for (std::size_t i = 0; i < f.size(); ++i) {
    // The row's instant in units of the motion's interval: the camera at that instant is motion^share * T_cw.
    const double share = shutter.readout_s * (double(sensor_rows[i]) / shutter.rows - 0.5) / dt;
    const Eigen::Matrix3d R = so3_exp(share * rotation);
    cv::KeyPoint& kp = f.keypoints[i];
    const bool with_depth = f.has_depth(i);
    const Eigen::Vector3d at_row = cam.unproject(kp.pt.x, kp.pt.y, with_depth ? f.depth[i] : 1.0);
    const Eigen::Vector3d moved = with_depth ? Eigen::Vector3d(at_row - share * translation) : at_row;
    const Eigen::Vector3d at_middle = R.transpose() * moved;
    if (at_middle.z() <= 0) continue;
    const Eigen::Vector2d p = cam.project(at_middle);
    kp.pt = cv::Point2f(static_cast<float>(p.x()), static_cast<float>(p.y()));
    if (with_depth) {
      f.depth[i] = static_cast<float>(at_middle.z());
      f.u_right[i] = static_cast<float>(p.x() - cam.bf / at_middle.z());
    }
  }
  f.build_grid();
}

}  // namespace varslam::slam
