#include "optim/reprojection.hpp"

#include <cmath>

#include "core/geometry.hpp"

namespace varslam::optim {

void pose_to_params(const Eigen::Isometry3d& T, double p[kPoseParams]) {
  const Eigen::Quaterniond q(T.rotation());
  p[0] = q.x();
  p[1] = q.y();
  p[2] = q.z();
  p[3] = q.w();
  p[4] = T.translation().x();
  p[5] = T.translation().y();
  p[6] = T.translation().z();
}

Eigen::Isometry3d params_to_pose(const double p[kPoseParams]) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(p[3], p[0], p[1], p[2]).normalized().toRotationMatrix();
  T.translation() << p[4], p[5], p[6];
  return T;
}

void pose_plus(const double x[kPoseParams], const double delta[6], double out[kPoseParams]) {
  const Eigen::Map<const Eigen::Quaterniond> q(x);
  const Eigen::Map<const Eigen::Vector3d> t(x + 4);
  const Eigen::Map<const Eigen::Vector3d> w(delta);
  const Eigen::Map<const Eigen::Vector3d> v(delta + 3);
  const double theta = w.norm();
  // Small angles: first-order quaternion, renormalised below (exact enough below 1e-10 rad).
  const Eigen::Quaterniond dq = theta > 1e-10 ? Eigen::Quaterniond(Eigen::AngleAxisd(theta, w / theta))
                                              : Eigen::Quaterniond(1.0, 0.5 * w.x(), 0.5 * w.y(), 0.5 * w.z());
  Eigen::Map<Eigen::Quaterniond> q_out(out);
  Eigen::Map<Eigen::Vector3d> t_out(out + 4);
  t_out = dq * t + v;
  q_out = (dq * q).normalized();
}

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  pose_plus(x, delta, x_plus_delta);
  return true;
}

bool PoseManifold::PlusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, kPoseParams, 6, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topRows<6>().setIdentity();
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Map<const Eigen::Quaterniond> qx(x), qy(y);
  const Eigen::Map<const Eigen::Vector3d> tx(x + 4), ty(y + 4);
  const Eigen::Quaterniond dq = qy * qx.conjugate();
  const Eigen::AngleAxisd aa(dq);
  Eigen::Map<Eigen::Vector3d> w(y_minus_x), v(y_minus_x + 3);
  w = aa.angle() * aa.axis();
  v = ty - dq * tx;
  return true;
}

bool PoseManifold::MinusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 6, kPoseParams, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.leftCols<6>().setIdentity();
  return true;
}

int whitened_residual(const PinholeCamera& cam, const Observation& obs, const Eigen::Vector3d& p_c, double e[3],
                      Eigen::Matrix3d* de_dpc) {
  // Keep z away from 0 so a point crossing the image plane gives a large finite residual, not inf/NaN
  // (Ceres aborts a solve on a non-finite residual at the initial point).
  constexpr double kMinAbsZ = 1e-6;
  const double z = std::abs(p_c.z()) < kMinAbsZ ? std::copysign(kMinAbsZ, p_c.z()) : p_c.z();
  const double iz = 1.0 / z;
  const double s = std::sqrt(obs.inv_sigma2);
  const double u = cam.fx * p_c.x() * iz + cam.cx;
  const double v = cam.fy * p_c.y() * iz + cam.cy;
  e[0] = s * (obs.uv.x() - u);
  e[1] = s * (obs.uv.y() - v);
  const int dof = obs.dof();
  const double w = obs.disparity_weight;
  if (dof == 3) e[2] = w > 0.0 ? s * w * ((obs.uv.x() - obs.u_right) - cam.bf * iz) : s * (obs.u_right - (u - cam.bf * iz));
  if (de_dpc) {
    const double iz2 = iz * iz;
    Eigen::Matrix3d& J = *de_dpc;
    J.row(0) << -s * cam.fx * iz, 0.0, s * cam.fx * p_c.x() * iz2;
    J.row(1) << 0.0, -s * cam.fy * iz, s * cam.fy * p_c.y() * iz2;
    if (dof != 3) J.row(2).setZero();
    else if (w > 0.0) J.row(2) << 0.0, 0.0, s * w * cam.bf * iz2;
    else J.row(2) << J(0, 0), 0.0, J(0, 2) - s * cam.bf * iz2;
  }
  return dof;
}

Eigen::Matrix<double, 3, 6> dpc_dpose(const Eigen::Vector3d& p_c) {
  Eigen::Matrix<double, 3, 6> J;
  J.leftCols<3>() = -skew(p_c);
  J.rightCols<3>().setIdentity();
  return J;
}

template <int Dof>
bool ReprojectionCost<Dof>::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Eigen::Quaterniond> q(parameters[0]);
  const Eigen::Map<const Eigen::Vector3d> t(parameters[0] + 4);
  const Eigen::Map<const Eigen::Vector3d> p_w(parameters[1]);
  const Eigen::Matrix3d R = q.toRotationMatrix();
  const Eigen::Vector3d p_c = R * p_w + t;
  double e[3];
  Eigen::Matrix3d J;
  whitened_residual(cam_, obs_, p_c, e, jacobians ? &J : nullptr);
  for (int i = 0; i < Dof; ++i) residuals[i] = e[i];
  if (!jacobians) return true;
  if (jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, Dof, kPoseParams, Eigen::RowMajor>> Jp(jacobians[0]);
    Jp.template leftCols<6>() = J.topRows<Dof>() * dpc_dpose(p_c);
    Jp.col(6).setZero();
  }
  if (jacobians[1]) {
    Eigen::Map<Eigen::Matrix<double, Dof, 3, Eigen::RowMajor>> Jx(jacobians[1]);
    Jx = J.topRows<Dof>() * R;
  }
  return true;
}

template <int Dof>
bool PoseOnlyCost<Dof>::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Eigen::Quaterniond> q(parameters[0]);
  const Eigen::Map<const Eigen::Vector3d> t(parameters[0] + 4);
  const Eigen::Vector3d p_c = q * p_w_ + t;
  double e[3];
  Eigen::Matrix3d J;
  const bool want_jacobian = jacobians && jacobians[0];
  whitened_residual(cam_, obs_, p_c, e, want_jacobian ? &J : nullptr);
  for (int i = 0; i < Dof; ++i) residuals[i] = e[i];
  if (want_jacobian) {
    Eigen::Map<Eigen::Matrix<double, Dof, kPoseParams, Eigen::RowMajor>> Jp(jacobians[0]);
    Jp.template leftCols<6>() = J.topRows<Dof>() * dpc_dpose(p_c);
    Jp.col(6).setZero();
  }
  return true;
}

template class ReprojectionCost<2>;
template class ReprojectionCost<3>;
template class PoseOnlyCost<2>;
template class PoseOnlyCost<3>;

}  // namespace varslam::optim
