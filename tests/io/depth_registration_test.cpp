// register_depth_to_colour: a separate depth camera's image moved into the colour camera's pixel grid.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>

#include "io/depth_image.hpp"

namespace varslam {
namespace {

PinholeCamera camera(double f, double cx, double cy) {
  PinholeCamera c;
  c.fx = c.fy = f;
  c.cx = cx;
  c.cy = cy;
  c.width = 64;
  c.height = 48;
  return c;
}

cv::Mat plane(float z) { return cv::Mat(48, 64, CV_32FC1, cv::Scalar(z)); }

TEST(RegisterDepth, IdenticalCamerasLeaveTheImageUnchanged) {
  cv::Mat d = plane(2.0f);
  d.at<float>(10, 20) = 1.0f;
  d.at<float>(30, 40) = 0.0f;  // a hole stays a hole
  DepthCameraRig rig{camera(50, 32, 24), Eigen::Vector3d::Zero()};
  const cv::Mat r = register_depth_to_colour(d, rig, camera(50, 32, 24));
  EXPECT_EQ(cv::norm(r, d, cv::NORM_INF), 0.0);
}

TEST(RegisterDepth, TranslationShiftsPixelsByTheParallax) {
  // A 1 m square patch in front of a 4 m wall; the depth camera sits 0.1 m to the colour camera's left, so the
  // patch appears f * 0.1 / 1 = 5 px further left in colour, the wall 1.25 px (rounded to 1).
  cv::Mat d = plane(4.0f);
  for (int v = 20; v < 28; ++v)
    for (int u = 28; u < 36; ++u) d.at<float>(v, u) = 1.0f;
  DepthCameraRig rig{camera(50, 32, 24), Eigen::Vector3d(-0.1, 0.0, 0.0)};
  const cv::Mat r = register_depth_to_colour(d, rig, camera(50, 32, 24));
  for (int u = 23; u < 31; ++u) EXPECT_FLOAT_EQ(r.at<float>(24, u), 1.0f) << "u=" << u;
  EXPECT_FLOAT_EQ(r.at<float>(24, 22), 4.0f);
  // Behind the patch's old right side the wall was occluded in depth: nothing lands there (no made-up depth).
  EXPECT_FLOAT_EQ(r.at<float>(24, 33), 0.0f);
  EXPECT_FLOAT_EQ(r.at<float>(24, 40), 4.0f);
}

TEST(RegisterDepth, NearerSurfaceWinsWhereTwoLandOnOnePixel) {
  // With a 0.1 m shift a point moves f * 0.1 / z px: z = 0.5 from u=35 and z = 1 from u=30 both land on u=25.
  cv::Mat d(48, 64, CV_32FC1, cv::Scalar(0.0f));
  d.at<float>(24, 35) = 0.5f;  // moves 10 px to u=25
  d.at<float>(24, 30) = 1.0f;  // moves 5 px to u=25
  DepthCameraRig rig{camera(50, 32, 24), Eigen::Vector3d(-0.1, 0.0, 0.0)};
  const cv::Mat r = register_depth_to_colour(d, rig, camera(50, 32, 24));
  EXPECT_FLOAT_EQ(r.at<float>(24, 25), 0.5f);
  EXPECT_EQ(cv::countNonZero(r), 1);
}

TEST(RegisterDepth, WiderColourLensPullsPixelsTowardsTheCentre) {
  // Depth f=60, colour f=50: a depth pixel 12 px right of the centre sits 10 px right of it in colour.
  cv::Mat d(48, 64, CV_32FC1, cv::Scalar(0.0f));
  d.at<float>(24 + 6, 32 + 12) = 2.0f;
  DepthCameraRig rig{camera(60, 32, 24), Eigen::Vector3d::Zero()};
  const cv::Mat r = register_depth_to_colour(d, rig, camera(50, 32, 24));
  EXPECT_FLOAT_EQ(r.at<float>(24 + 5, 32 + 10), 2.0f);
  EXPECT_EQ(cv::countNonZero(r), 1);
}

TEST(RegisterDepth, OutputHasTheColourCameraSize) {
  PinholeCamera colour = camera(50, 40, 30);
  colour.width = 80;
  colour.height = 60;
  DepthCameraRig rig{camera(50, 32, 24), Eigen::Vector3d::Zero()};
  const cv::Mat r = register_depth_to_colour(plane(1.0f), rig, colour);
  EXPECT_EQ(r.cols, 80);
  EXPECT_EQ(r.rows, 60);
  EXPECT_FLOAT_EQ(r.at<float>(30, 40), 1.0f);  // principal points coincide
  EXPECT_FLOAT_EQ(r.at<float>(2, 2), 0.0f);     // outside what the depth camera sees
}

// The warp as first written (std::lround per pixel), to hold the faster rounding to the same pixels.
cv::Mat reference_registration(const cv::Mat& depth_m, const DepthCameraRig& rig, const PinholeCamera& colour) {
  cv::Mat out(colour.height, colour.width, CV_32FC1, cv::Scalar(0.0f));
  for (int v = 0; v < depth_m.rows; ++v)
    for (int u = 0; u < depth_m.cols; ++u) {
      const float z = depth_m.at<float>(v, u);
      if (!(z > 0.0f)) continue;
      const Eigen::Vector3d p = rig.depth.unproject(u, v, z) + rig.t_colour_depth;
      if (p.z() <= 0.0) continue;
      const Eigen::Vector2d uv = colour.project(p);
      const long cu = std::lround(uv.x()), cv_ = std::lround(uv.y());
      if (cu < 0 || cv_ < 0 || cu >= out.cols || cv_ >= out.rows) continue;
      float& dst = out.at<float>(static_cast<int>(cv_), static_cast<int>(cu));
      if (dst == 0.0f || static_cast<float>(p.z()) < dst) dst = static_cast<float>(p.z());
    }
  return out;
}

TEST(RegisterDepth, PixelsAreThoseStdLroundNamesIncludingHalfWayAndTheBorders) {
  // An odd width too, so a row split into blocks of pixels cannot hide a wrong last block.
  for (const int cols : {64, 63}) {
    cv::RNG rng(3);
    cv::Mat d(48, cols, CV_32FC1);
    rng.fill(d, cv::RNG::UNIFORM, 0.3, 4.0);
    for (int i = 0; i < 200; ++i) d.at<float>(rng.uniform(0, 48), rng.uniform(0, cols)) = 0.0f;
    // Half a pixel between the cameras' centres: many projections land on (or a hair off) x.5, and the shifts and
    // translations push pixels across every border; the last puts near points behind the colour camera.
    for (const auto& [shift, t] :
         {std::pair{0.5, Eigen::Vector3d(0, 0, 0)}, std::pair{-0.5, Eigen::Vector3d(0.05, -0.03, 0)},
          std::pair{3.25, Eigen::Vector3d(-0.2, 0.1, 0.02)}, std::pair{1.5, Eigen::Vector3d(0.1, 0, -0.5)}}) {
      DepthCameraRig rig{camera(50, 32, 24), t};
      const PinholeCamera colour = camera(50, 32 + shift, 24 - shift);
      const cv::Mat r = register_depth_to_colour(d, rig, colour);
      EXPECT_EQ(cv::norm(r, reference_registration(d, rig, colour), cv::NORM_INF), 0.0)
          << "cols " << cols << " shift " << shift;
      EXPECT_GT(cv::countNonZero(r), 300);
    }
  }
}

}  // namespace
}  // namespace varslam
