#include "core/geometry.hpp"

#include <cmath>

namespace varslam {

Eigen::Matrix3d so3_exp(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  if (theta < 1e-12) return Eigen::Matrix3d::Identity() + skew(w);
  return Eigen::AngleAxisd(theta, w / theta).toRotationMatrix();
}

Eigen::Vector3d so3_log(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Isometry3d se3_left_update(const Eigen::Isometry3d& T, const Eigen::Matrix<double, 6, 1>& xi) {
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  D.linear() = so3_exp(xi.head<3>());
  D.translation() = xi.tail<3>();
  return D * T;
}

Eigen::Isometry3d normalized(const Eigen::Isometry3d& T) {
  Eigen::Isometry3d out = T;
  out.linear() = Eigen::Quaterniond(T.rotation()).normalized().toRotationMatrix();
  return out;
}

double rotation_angle(const Eigen::Matrix3d& Ra, const Eigen::Matrix3d& Rb) {
  return Eigen::AngleAxisd(Ra.transpose() * Rb).angle();
}

bool views_may_overlap(const Eigen::Isometry3d& T_wa, const Eigen::Isometry3d& T_wb, double max_angle_deg,
                       double max_distance_m) {
  return T_wa.linear().col(2).dot(T_wb.linear().col(2)) >= std::cos(max_angle_deg * M_PI / 180.0) &&
         (T_wa.translation() - T_wb.translation()).norm() <= max_distance_m;
}

}  // namespace varslam
