#pragma once
// Reprojection residuals with analytic Jacobians, the pose parameter block and its SE(3) manifold.
// Shared by the pose-only optimisers and Local BA.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/manifold.h>
#include <ceres/sized_cost_function.h>

#include "core/camera.hpp"

namespace varslam::optim {

/// One keypoint observing one point.
struct Observation {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // undistorted pixel
  double u_right = -1.0;                         // virtual right coordinate u - bf/depth; < 0 = monocular
  double inv_sigma2 = 1.0;                       // information scale of the keypoint's pyramid level
  // Depth term: 0 = ORB-SLAM3's residual on the virtual right coordinate u_r (one pixel of noise, as a stereo
  // match); > 0 = residual on the disparity bf/z alone, weighted by this ratio of keypoint to disparity sigma.
  double disparity_weight = 0.0;
  bool stereo() const { return u_right >= 0.0; }
  int dof() const { return stereo() ? 3 : 2; }
};

/// Pose block layout: [qx qy qz qw tx ty tz] of T_cw (Eigen's quaternion coefficient order).
inline constexpr int kPoseParams = 7;
void pose_to_params(const Eigen::Isometry3d& T, double p[kPoseParams]);
Eigen::Isometry3d params_to_pose(const double p[kPoseParams]);
/// Left update exp([w; v]) * T in the sense of core/geometry's se3_left_update: R' = exp(w) R,
/// t' = exp(w) t + v. Both solvers use it, so their tangent Jacobians agree.
void pose_plus(const double x[kPoseParams], const double delta[6], double out[kPoseParams]);

/// Manifold on the 7-vector with the left update above. The tangent Jacobian of a residual is written by the
/// cost functions into the first 6 ambient columns (7th column zero) and PlusJacobian is [I6; 0]: Ceres
/// multiplies the two, so the solver sees the exact tangent Jacobian with no quaternion chain rule.
class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseParams; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

/// Whitened residual e = sqrt(inv_sigma2) * (measured - projected) of one observation of the camera-frame
/// point p_c, and optionally d e / d p_c (dof x 3, row-major in a 3x3). Returns the dof (2 or 3).
int whitened_residual(const PinholeCamera& cam, const Observation& obs, const Eigen::Vector3d& p_c, double e[3],
                      Eigen::Matrix3d* de_dpc);

/// Squared whitened residual (what the chi-square gates test) of one observation of p_c; dof is set to 2 or 3.
inline double whitened_chi2(const PinholeCamera& cam, const Observation& obs, const Eigen::Vector3d& p_c, int& dof) {
  double e[3];
  dof = whitened_residual(cam, obs, p_c, e, nullptr);
  double chi2 = 0;
  for (int k = 0; k < dof; ++k) chi2 += e[k] * e[k];
  return chi2;
}

/// d p_c / d [w; v] for the left update at p_c = T_cw * p_w: [-[p_c]x, I].
Eigen::Matrix<double, 3, 6> dpc_dpose(const Eigen::Vector3d& p_c);

/// BA residual on (pose block, point block). Dof = 2 (mono) or 3 (stereo / RGB-D).
template <int Dof>
class ReprojectionCost final : public ceres::SizedCostFunction<Dof, kPoseParams, 3> {
 public:
  ReprojectionCost(const PinholeCamera& cam, const Observation& obs) : cam_(cam), obs_(obs) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  PinholeCamera cam_;
  Observation obs_;
};

/// Pose-only residual: the world point is a constant of the cost.
template <int Dof>
class PoseOnlyCost final : public ceres::SizedCostFunction<Dof, kPoseParams> {
 public:
  PoseOnlyCost(const PinholeCamera& cam, const Observation& obs, const Eigen::Vector3d& p_w)
      : cam_(cam), obs_(obs), p_w_(p_w) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  PinholeCamera cam_;
  Observation obs_;
  Eigen::Vector3d p_w_;
};

extern template class ReprojectionCost<2>;
extern template class ReprojectionCost<3>;
extern template class PoseOnlyCost<2>;
extern template class PoseOnlyCost<3>;

}  // namespace varslam::optim
