#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

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

// Keypoints of a strongly distorted camera (TUM freiburg1's Kinect v1 colour camera) undistorted: projecting the
// result with the distortion model gives the pixel back, also at the image's corners.
TEST(Camera, UndistortedPixelsProjectBackToTheDistortedOnesUpToTheCorners) {
  PinholeCamera cam;
  cam.fx = 517.3, cam.fy = 516.5, cam.cx = 318.6, cam.cy = 255.3;
  cam.k1 = 0.2624, cam.k2 = -0.9531, cam.p1 = -0.0054, cam.p2 = 0.0026, cam.k3 = 1.1633;
  const std::vector<cv::Point2f> px{{2, 2}, {637, 3}, {5, 476}, {320, 240}, {600, 400}, {40, 30}};
  const std::vector<cv::Point2f> und = undistort_pixels(cam, px);
  ASSERT_EQ(und.size(), px.size());
  std::vector<cv::Point3d> rays;
  for (const auto& p : und) rays.emplace_back((p.x - cam.cx) / cam.fx, (p.y - cam.cy) / cam.fy, 1.0);
  std::vector<cv::Point2d> back;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cam.K(), cam.dist_coeffs(), back);
  for (std::size_t i = 0; i < px.size(); ++i) {
    EXPECT_NEAR(back[i].x, px[i].x, 0.01) << px[i];
    EXPECT_NEAR(back[i].y, px[i].y, 0.01) << px[i];
  }
  EXPECT_GT(std::abs(und[0].x - px[0].x), 3.0f);  // the corners do move
  EXPECT_TRUE(undistort_pixels(cam, {}).empty());
}

}  // namespace
}  // namespace varslam
