#pragma once
// Small SE(3)/SO(3) helpers on top of Eigen.
#include <Eigen/Geometry>

namespace varslam {

inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

/// Rotation matrix from a rotation vector (axis * angle).
Eigen::Matrix3d so3_exp(const Eigen::Vector3d& w);
/// Rotation vector (axis * angle) of a rotation matrix.
Eigen::Vector3d so3_log(const Eigen::Matrix3d& R);
/// Pose from a 6-vector [rotation vector; translation] applied as a left update: exp(xi) * T.
Eigen::Isometry3d se3_left_update(const Eigen::Isometry3d& T, const Eigen::Matrix<double, 6, 1>& xi);
/// Re-orthonormalise the rotation part (accumulated round-off after many compositions).
Eigen::Isometry3d normalized(const Eigen::Isometry3d& T);
/// Rotation angle in radians between two rotations.
double rotation_angle(const Eigen::Matrix3d& Ra, const Eigen::Matrix3d& Rb);
/// Whether two cameras (camera-to-world poses) may see the same surface: optical axes at most `max_angle_deg`
/// apart and centres at most `max_distance_m` apart.
bool views_may_overlap(const Eigen::Isometry3d& T_wa, const Eigen::Isometry3d& T_wb, double max_angle_deg,
                       double max_distance_m);

}  // namespace varslam
