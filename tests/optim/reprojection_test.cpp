#include <gtest/gtest.h>

#include "core/geometry.hpp"
#include "optim/reprojection.hpp"

namespace varslam::optim {
namespace {

Eigen::Isometry3d test_pose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3_exp(Eigen::Vector3d(0.2, -0.1, 0.3));
  T.translation() << 0.4, -0.2, 0.5;
  return T;
}

Observation test_obs(bool stereo, double disparity_weight = 0.0) {
  Observation o;
  o.disparity_weight = disparity_weight;
  o.uv << 300.0, 200.0;
  o.u_right = stereo ? 285.0 : -1.0;
  o.inv_sigma2 = 1.0 / (1.2 * 1.2);
  return o;
}

// Tangent Jacobian by central differences through the manifold's Plus (the update the solver applies).
template <int Dof>
void check_ba_jacobians(bool stereo, double disparity_weight = 0.0) {
  const PinholeCamera cam;
  const ReprojectionCost<Dof> cost(cam, test_obs(stereo, disparity_weight));
  double x[kPoseParams];
  pose_to_params(test_pose(), x);
  double p[3] = {0.3, -0.4, 4.0};
  double r[Dof], J_pose[Dof * kPoseParams], J_point[Dof * 3];
  const double* params[2] = {x, p};
  double* jac[2] = {J_pose, J_point};
  ASSERT_TRUE(cost.Evaluate(params, r, jac));
  const PoseManifold manifold;
  double J_tangent[kPoseParams * 6];
  manifold.PlusJacobian(x, J_tangent);
  const Eigen::Matrix<double, Dof, 6> analytic_pose =
      Eigen::Map<Eigen::Matrix<double, Dof, kPoseParams, Eigen::RowMajor>>(J_pose) *
      Eigen::Map<Eigen::Matrix<double, kPoseParams, 6, Eigen::RowMajor>>(J_tangent);

  const double h = 1e-6;
  for (int c = 0; c < 6; ++c) {
    double d[6] = {0, 0, 0, 0, 0, 0}, xp[kPoseParams], xm[kPoseParams], rp[Dof], rm[Dof];
    d[c] = h;
    manifold.Plus(x, d, xp);
    d[c] = -h;
    manifold.Plus(x, d, xm);
    const double* pp[2] = {xp, p};
    const double* pm[2] = {xm, p};
    cost.Evaluate(pp, rp, nullptr);
    cost.Evaluate(pm, rm, nullptr);
    for (int i = 0; i < Dof; ++i)
      EXPECT_NEAR(analytic_pose(i, c), (rp[i] - rm[i]) / (2 * h), 1e-4 * (1 + std::abs(analytic_pose(i, c))))
          << "pose row " << i << " col " << c;
  }
  for (int c = 0; c < 3; ++c) {
    double pp3[3] = {p[0], p[1], p[2]}, pm3[3] = {p[0], p[1], p[2]}, rp[Dof], rm[Dof];
    pp3[c] += h;
    pm3[c] -= h;
    const double* pp[2] = {x, pp3};
    const double* pm[2] = {x, pm3};
    cost.Evaluate(pp, rp, nullptr);
    cost.Evaluate(pm, rm, nullptr);
    for (int i = 0; i < Dof; ++i)
      EXPECT_NEAR(J_point[i * 3 + c], (rp[i] - rm[i]) / (2 * h), 1e-4 * (1 + std::abs(J_point[i * 3 + c])))
          << "point row " << i << " col " << c;
  }
}

TEST(Reprojection, MonoJacobiansMatchNumeric) { check_ba_jacobians<2>(false); }
TEST(Reprojection, StereoJacobiansMatchNumeric) { check_ba_jacobians<3>(true); }
TEST(Reprojection, DisparityJacobiansMatchNumeric) { check_ba_jacobians<3>(true, 4.0); }

TEST(Reprojection, PoseOnlyCostMatchesBaCost) {
  const PinholeCamera cam;
  const Observation o = test_obs(true);
  double p[3] = {-0.5, 0.2, 3.0};
  const PoseOnlyCost<3> pose_only(cam, o, Eigen::Vector3d(p[0], p[1], p[2]));
  const ReprojectionCost<3> ba(cam, o);
  double x[kPoseParams];
  pose_to_params(test_pose(), x);
  double r1[3], r2[3], J1[3 * kPoseParams], J2[3 * kPoseParams], Jx[9];
  const double* p1[1] = {x};
  const double* p2[2] = {x, p};
  double* j1[1] = {J1};
  double* j2[2] = {J2, Jx};
  ASSERT_TRUE(pose_only.Evaluate(p1, r1, j1));
  ASSERT_TRUE(ba.Evaluate(p2, r2, j2));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(r1[i], r2[i], 1e-9);
  for (int i = 0; i < 3 * kPoseParams; ++i) EXPECT_NEAR(J1[i], J2[i], 1e-9);
}

TEST(Reprojection, ResidualIsWhitenedMeasuredMinusProjected) {
  PinholeCamera cam;
  const Eigen::Vector3d p_c(0.2, -0.1, 2.0);
  const Eigen::Vector2d uv = cam.project(p_c);
  Observation o;
  o.uv = uv + Eigen::Vector2d(2.0, -1.0);
  o.u_right = uv.x() - cam.bf / p_c.z() + 4.0;
  o.inv_sigma2 = 0.25;  // sigma 2 px
  double e[3];
  ASSERT_EQ(whitened_residual(cam, o, p_c, e, nullptr), 3);
  EXPECT_NEAR(e[0], 1.0, 1e-12);
  EXPECT_NEAR(e[1], -0.5, 1e-12);
  EXPECT_NEAR(e[2], 2.0, 1e-12);
  o.u_right = -1;
  EXPECT_EQ(whitened_residual(cam, o, p_c, e, nullptr), 2);
}

// With a disparity weight the depth term measures disparity alone: a keypoint offset in u leaves it untouched,
// a depth error shows up weighted.
TEST(Reprojection, DisparityResidualIgnoresKeypointOffsetAndWeightsDepth) {
  PinholeCamera cam;
  const Eigen::Vector3d p_c(0.2, -0.1, 2.0);
  const Eigen::Vector2d uv = cam.project(p_c);
  Observation o;
  o.uv = uv + Eigen::Vector2d(2.0, 0.0);
  const double measured_disparity = cam.bf / p_c.z() + 0.5;
  o.u_right = o.uv.x() - measured_disparity;
  o.inv_sigma2 = 0.25;
  o.disparity_weight = 8.0;
  double e[3];
  ASSERT_EQ(whitened_residual(cam, o, p_c, e, nullptr), 3);
  EXPECT_NEAR(e[0], 1.0, 1e-12);
  EXPECT_NEAR(e[2], 0.5 * 8.0 * 0.5, 1e-9);
  o.disparity_weight = 0.0;  // ORB-SLAM3's u_r residual mixes the keypoint offset in: (2 - 0.5) / 2
  ASSERT_EQ(whitened_residual(cam, o, p_c, e, nullptr), 3);
  EXPECT_NEAR(e[2], 0.75, 1e-9);
}

TEST(PoseManifold, PlusMatchesLeftUpdateAndMinusInvertsIt) {
  const Eigen::Isometry3d T = test_pose();
  double x[kPoseParams], y[kPoseParams], back[6];
  pose_to_params(T, x);
  Eigen::Matrix<double, 6, 1> xi;
  xi << 0.1, -0.2, 0.05, 0.3, 0.1, -0.2;
  const PoseManifold m;
  ASSERT_TRUE(m.Plus(x, xi.data(), y));
  const Eigen::Isometry3d expected = se3_left_update(T, xi);
  EXPECT_TRUE(params_to_pose(y).matrix().isApprox(expected.matrix(), 1e-12));
  ASSERT_TRUE(m.Minus(y, x, back));
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(back[i], xi[i], 1e-12);
}

}  // namespace
}  // namespace varslam::optim
