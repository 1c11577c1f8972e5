// Dense alignment of two depth images (slam/dense_alignment.hpp) on a room whose geometry is known: the relative
// pose between two views is recovered from a guess centimetres and degrees off.
#include "slam/dense_alignment.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "core/geometry.hpp"

namespace varslam::slam {
namespace {

// Depth (metres) seen from camera-to-world pose T_wc inside an axis-aligned box room [-2, 2] x [-1.5, 1.5] x
// [-1, 4], plus a block on the floor so that no direction slides freely.
cv::Mat room_depth(const PinholeCamera& cam, const Eigen::Isometry3d& T_wc) {
  cv::Mat depth(cam.height, cam.width, CV_32FC1, cv::Scalar(0.0f));
  const Eigen::Vector3d lo(-2, -1.5, -1), hi(2, 1.5, 4);
  const Eigen::Vector3d block_lo(-0.6, 0.9, 2.0), block_hi(0.2, 1.5, 2.6);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d ray_c = cam.unproject(u, v, 1.0);
      const Eigen::Vector3d o = T_wc.translation(), d = T_wc.linear() * ray_c;
      double t_best = 1e9;
      for (int a = 0; a < 3; ++a) {  // the room's walls, from inside: the far one along each axis
        if (std::abs(d[a]) < 1e-12) continue;
        const double t = ((d[a] > 0 ? hi[a] : lo[a]) - o[a]) / d[a];
        if (t > 0) t_best = std::min(t_best, t);
      }
      double t_in = 0, t_out = 1e9;  // the block, from outside (slab test)
      bool hit = true;
      for (int a = 0; a < 3 && hit; ++a) {
        if (std::abs(d[a]) < 1e-12) {
          hit = o[a] > block_lo[a] && o[a] < block_hi[a];
          continue;
        }
        double t0 = (block_lo[a] - o[a]) / d[a], t1 = (block_hi[a] - o[a]) / d[a];
        if (t0 > t1) std::swap(t0, t1);
        t_in = std::max(t_in, t0);
        t_out = std::min(t_out, t1);
      }
      if (hit && t_in < t_out && t_in > 0) t_best = std::min(t_best, t_in);
      depth.at<float>(v, u) = static_cast<float>(t_best * ray_c.z());
    }
  return depth;
}

Eigen::Isometry3d pose(double yaw_deg, double pitch_deg, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(pitch_deg * M_PI / 180, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = t;
  return T;
}

TEST(DenseAlignment, TheSampleHasEveryFourthPixelInMillimetres) {
  cv::Mat d(480, 640, CV_32FC1, cv::Scalar(2.0f));
  d.at<float>(4, 8) = 0.0f;
  d.at<float>(8, 4) = std::numeric_limits<float>::quiet_NaN();
  const DepthSample s = DepthSample::of(d);
  ASSERT_EQ(s.depth_mm.size(), cv::Size(160, 120));
  EXPECT_EQ(s.depth_mm.at<std::uint16_t>(0, 0), 2000);
  EXPECT_EQ(s.depth_mm.at<std::uint16_t>(1, 2), 0);  // no depth stays no depth
  EXPECT_EQ(s.depth_mm.at<std::uint16_t>(2, 1), 0);  // nor does NaN become a number
  EXPECT_TRUE(DepthSample::of(cv::Mat()).empty());
}

// Per-pixel noise averages out over the sampled pixel's neighbourhood, but a depth edge is never averaged across: a
// sample beside the edge keeps its own side's depth.
TEST(DenseAlignment, TheSampleAveragesNoiseButNotAcrossADepthEdge) {
  cv::Mat d(480, 640, CV_32FC1);
  cv::RNG rng(3);
  for (int r = 0; r < d.rows; ++r)
    for (int c = 0; c < d.cols; ++c)
      d.at<float>(r, c) = static_cast<float>((c < 322 ? 3.0 : 1.5) + rng.gaussian(0.015));
  const DepthSample s = DepthSample::of(d);
  double sum_sq = 0;
  int n = 0;
  for (int r = 1; r + 1 < s.depth_mm.rows; ++r)
    for (int c = 1; c < 80; ++c) {
      sum_sq += std::pow(s.depth_mm.at<std::uint16_t>(r, c) - 3000.0, 2);
      ++n;
    }
  EXPECT_LT(std::sqrt(sum_sq / n), 15.0 / 3);  // 25 pixels: a fifth of the noise, up to the tolerance's clipping
  for (int r = 1; r + 1 < s.depth_mm.rows; ++r) {
    EXPECT_NEAR(s.depth_mm.at<std::uint16_t>(r, 80), 3000, 40);   // pixel 320: its window reaches 2 px past the edge
    EXPECT_NEAR(s.depth_mm.at<std::uint16_t>(r, 81), 1500, 20);   // pixel 324
  }
}

// A mover's pixels are neither sampled nor averaged into the samples beside them.
TEST(DenseAlignment, TheSampleLeavesOutWhatTheMoverMaskCovers) {
  cv::Mat d(480, 640, CV_32FC1, cv::Scalar(2.0f));
  cv::Mat mask = cv::Mat::zeros(d.size(), CV_8UC1);
  d(cv::Rect(100, 98, 50, 50)).setTo(2.03f);  // a mover just off the wall, within the averaging tolerance
  mask(cv::Rect(100, 98, 50, 50)).setTo(255);
  const DepthSample s = DepthSample::of(d, mask);
  EXPECT_EQ(s.depth_mm.at<std::uint16_t>(30, 30), 0);     // pixel (120, 120): on the mover
  EXPECT_EQ(s.depth_mm.at<std::uint16_t>(24, 30), 2000);  // pixel (120, 96): the wall beside it, its own depth
  EXPECT_EQ(DepthSample::of(d).depth_mm.at<std::uint16_t>(24, 30), 2006);  // unmasked, the mover's row joins in
  EXPECT_THROW(DepthSample::of(d, cv::Mat::zeros(10, 10, CV_8UC1)), std::invalid_argument);
}

TEST(DenseAlignment, RecoversTheRelativePoseFromAGuessCentimetresOff) {
  const PinholeCamera cam;
  const Eigen::Isometry3d T_w_target = pose(0, -10, {0.1, 0.2, 0.0});
  const Eigen::Isometry3d T_w_source = pose(12, -5, {0.4, 0.1, 0.3});
  const Surface target = surface_of(DepthSample::of(room_depth(cam, T_w_target)), cam);
  const Surface source = surface_of(DepthSample::of(room_depth(cam, T_w_source)), cam);
  const Eigen::Isometry3d truth = T_w_target.inverse() * T_w_source;
  Eigen::Isometry3d guess = truth;
  guess.translation() += Eigen::Vector3d(0.03, -0.02, 0.02);
  guess.linear() = guess.linear() * so3_exp(Eigen::Vector3d(0.01, -0.02, 0.015));
  const std::optional<DenseAlignment> a = align_surfaces(target, source, guess);
  ASSERT_TRUE(a);
  const Eigen::Isometry3d err = truth.inverse() * a->T_target_source;
  EXPECT_LT(err.translation().norm(), 0.002);
  EXPECT_LT(Eigen::AngleAxisd(err.linear()).angle() * 180 / M_PI, 0.1);
  EXPECT_GT(a->overlap, 0.6);
  EXPECT_LT(a->rms_m, 0.002);
}

TEST(DenseAlignment, ViewsThatDoNotOverlapGiveNoAlignment) {
  const PinholeCamera cam;
  const Surface target = surface_of(DepthSample::of(room_depth(cam, pose(0, 0, {0, 0, 0}))), cam);
  const Surface source = surface_of(DepthSample::of(room_depth(cam, pose(180, 0, {0, 0, 1}))), cam);
  // Guessed as the truth: the source looks the other way, so none of its points lands in the target's view.
  const Eigen::Isometry3d truth = pose(0, 0, {0, 0, 0}).inverse() * pose(180, 0, {0, 0, 1});
  EXPECT_FALSE(align_surfaces(target, source, truth));
}

}  // namespace
}  // namespace varslam::slam
