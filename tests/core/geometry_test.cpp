#include <gtest/gtest.h>

#include "core/camera.hpp"
#include "core/geometry.hpp"

namespace varslam {
namespace {

TEST(Geometry, So3ExpLogRoundTrip) {
  const Eigen::Vector3d w(0.3, -0.2, 1.1);
  EXPECT_TRUE(so3_log(so3_exp(w)).isApprox(w, 1e-12));
}

TEST(Geometry, LeftUpdateComposes) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() << 1, 2, 3;
  Eigen::Matrix<double, 6, 1> xi;
  xi << 0, 0, M_PI / 2, 0.5, 0, 0;
  const Eigen::Isometry3d U = se3_left_update(T, xi);
  // Rotating (1,2,3) by 90 degrees about z gives (-2,1,3), then the translation adds (0.5,0,0).
  EXPECT_TRUE(U.translation().isApprox(Eigen::Vector3d(-1.5, 1, 3), 1e-12));
  EXPECT_NEAR(rotation_angle(U.rotation(), T.rotation()), M_PI / 2, 1e-12);
}

TEST(Camera, ProjectUnprojectRoundTrip) {
  PinholeCamera cam;
  const Eigen::Vector3d p = cam.unproject(100.25, 300.5, 2.5);
  const Eigen::Vector2d uv = cam.project(p);
  EXPECT_NEAR(uv.x(), 100.25, 1e-12);
  EXPECT_NEAR(uv.y(), 300.5, 1e-12);
  EXPECT_DOUBLE_EQ(p.z(), 2.5);
  EXPECT_FALSE(cam.in_image(-1, 10));
  EXPECT_TRUE(cam.in_image(639.5, 479.5));
}

}  // namespace
}  // namespace varslam
