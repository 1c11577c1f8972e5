// Depth-to-colour registration found from the images: a known misregistration is recovered, registered
// images are left alone, and the real 7-Scenes frames (when ../shared is present) come out as the Kinect
// colour camera (focal about 530, not the depth camera's 585).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/colour_registration.hpp"
#include "io/depth_image.hpp"

namespace varslam {
namespace {

namespace fs = std::filesystem;

PinholeCamera depth_camera() {
  PinholeCamera c;
  c.fx = c.fy = 585.0;
  c.cx = 320.0;
  c.cy = 240.0;
  c.bf = 585.0 * 0.075;
  return c;
}

// A wall 4 m away with a few boxes 1-2 m in front, different per frame.
cv::Mat depth_scene(int seed) {
  cv::Mat d(480, 640, CV_32FC1, cv::Scalar(4.0f));
  std::mt19937 rng(static_cast<unsigned>(seed));
  std::uniform_int_distribution<int> x(20, 500), y(20, 360), w(40, 120);
  std::uniform_real_distribution<float> z(1.0f, 2.0f);
  for (int k = 0; k < 5; ++k) cv::rectangle(d, cv::Rect(x(rng), y(rng), w(rng), w(rng)), cv::Scalar(z(rng)), cv::FILLED);
  return d;
}

// The colour image the colour camera sees: each colour pixel looks up the depth pixel it maps back to
// (inverse of colour = s (depth - c) + c + shift); near surfaces are bright, the wall dark, plus noise.
cv::Mat colour_view(const cv::Mat& depth, const PinholeCamera& d, double s, double du, double dv, int seed) {
  cv::Mat gray(depth.size(), CV_8UC1);
  std::mt19937 rng(static_cast<unsigned>(seed) + 100);
  std::normal_distribution<double> noise(0.0, 4.0);
  for (int v = 0; v < gray.rows; ++v)
    for (int u = 0; u < gray.cols; ++u) {
      const int ud = static_cast<int>(std::lround((u - d.cx - du) / s + d.cx));
      const int vd = static_cast<int>(std::lround((v - d.cy - dv) / s + d.cy));
      const bool inside = ud >= 0 && vd >= 0 && ud < depth.cols && vd < depth.rows;
      const double base = inside && depth.at<float>(vd, ud) < 3.0f ? 180.0 : 70.0;
      gray.at<std::uint8_t>(v, u) = cv::saturate_cast<std::uint8_t>(base + noise(rng));
    }
  return gray;
}

TEST(ColourRegistration, RecoversAKnownZoomAndShift) {
  const PinholeCamera d = depth_camera();
  std::vector<cv::Mat> grays, depths;
  for (int i = 0; i < 6; ++i) {
    depths.push_back(depth_scene(i));
    grays.push_back(colour_view(depths.back(), d, 0.905, -7.0, 2.0, i));
  }
  const ColourRegistration r = estimate_colour_registration(grays, depths, d);
  EXPECT_TRUE(r.found);
  EXPECT_NEAR(r.scale, 0.905, 0.006);
  EXPECT_NEAR(r.du, -7.0, 1.01);
  EXPECT_NEAR(r.dv, 2.0, 1.01);
  EXPECT_GT(r.score, 1.25 * r.identity_score);
  const PinholeCamera c = r.colour_camera(d);
  EXPECT_NEAR(c.fx, 0.905 * 585.0, 4.0);
  EXPECT_NEAR(c.cx, 313.0, 1.01);
  EXPECT_NEAR(c.bf / c.fx, d.bf / d.fx, 1e-12) << "the baseline in metres is kept";
}

// The colour image of a colour camera `tx` metres beside the depth camera (depth origin in the colour frame at
// (tx, 0, 0)): near surfaces bright, the wall and pixels nothing lands on dark, plus noise.
cv::Mat colour_view_with_baseline(const cv::Mat& depth, const PinholeCamera& d, const PinholeCamera& colour, double tx,
                                  int seed) {
  DepthCameraRig rig;
  rig.depth = d;
  rig.t_colour_depth = {tx, 0.0, 0.0};
  const cv::Mat z = register_depth_to_colour(depth, rig, colour);
  cv::Mat gray(depth.size(), CV_8UC1);
  std::mt19937 rng(static_cast<unsigned>(seed) + 100);
  std::normal_distribution<double> noise(0.0, 4.0);
  for (int v = 0; v < gray.rows; ++v)
    for (int u = 0; u < gray.cols; ++u) {
      const float zc = z.at<float>(v, u);
      gray.at<std::uint8_t>(v, u) = cv::saturate_cast<std::uint8_t>((zc > 0 && zc < 3.0f ? 180.0 : 70.0) + noise(rng));
    }
  return gray;
}

// A shift alone fits the baseline's parallax at one depth only; the boxes at 1-2 m and the wall at 4 m tell it.
TEST(ColourRegistration, RecoversTheBaselineBetweenTheCameras) {
  const PinholeCamera d = depth_camera();
  PinholeCamera colour = d;
  colour.fx = colour.fy = 0.9 * d.fx;
  colour.cx = d.cx + 3.0;
  colour.cy = d.cy - 1.0;
  std::vector<cv::Mat> grays, depths;
  for (int i = 0; i < 8; ++i) {
    depths.push_back(depth_scene(i));
    grays.push_back(colour_view_with_baseline(depths.back(), d, colour, -0.03, i));
  }
  const ColourRegistration r = estimate_colour_registration(grays, depths, d);
  EXPECT_TRUE(r.found);
  EXPECT_NEAR(r.baseline_x, -0.03, 0.004);
  EXPECT_NEAR(r.scale, 0.9, 0.006);
  EXPECT_NEAR(r.du, 3.0, 1.51);
  EXPECT_NEAR(r.dv, -1.0, 1.01);
  ColourRegistrationSearch shift_only;
  shift_only.max_baseline_m = 0.0;
  const ColourRegistration s = estimate_colour_registration(grays, depths, d, shift_only);
  EXPECT_EQ(s.baseline_x, 0.0);
  EXPECT_GT(r.score, 1.05 * s.score) << "the baseline fits the edges at every depth, a shift at one";
}

TEST(ColourRegistration, RegisteredImagesStayIdentity) {
  const PinholeCamera d = depth_camera();
  std::vector<cv::Mat> grays, depths;
  for (int i = 0; i < 6; ++i) {
    depths.push_back(depth_scene(i));
    grays.push_back(colour_view(depths.back(), d, 1.0, 0.0, 0.0, i));
  }
  const ColourRegistration r = estimate_colour_registration(grays, depths, d);
  EXPECT_FALSE(r.found);
  EXPECT_NEAR(r.scale, 1.0, 0.003);
  EXPECT_NEAR(r.du, 0.0, 1.01);
  EXPECT_NEAR(r.dv, 0.0, 1.01);
  EXPECT_NEAR(r.baseline_x, 0.0, 0.003);
}

TEST(ColourRegistration, NoDepthEdgesIsNotFound) {
  const std::vector<cv::Mat> depths{cv::Mat(480, 640, CV_32FC1, cv::Scalar(2.0f))};
  const std::vector<cv::Mat> grays{cv::Mat(480, 640, CV_8UC1, cv::Scalar(100))};
  const ColourRegistration r = estimate_colour_registration(grays, depths, depth_camera());
  EXPECT_FALSE(r.found);
  EXPECT_EQ(r.frames, 0);
}

TEST(ColourRegistration, OccludingEdgesAreOnTheNearSide) {
  cv::Mat d(40, 40, CV_32FC1, cv::Scalar(3.0f));
  d(cv::Rect(10, 10, 10, 10)).setTo(1.0f);
  for (const cv::Point& p : occluding_edge_pixels(d)) {
    EXPECT_FLOAT_EQ(d.at<float>(p), 1.0f) << p;
    EXPECT_TRUE(p.x == 10 || p.x == 19 || p.y == 10 || p.y == 19) << p;
  }
  EXPECT_EQ(occluding_edge_pixels(d).size(), 36u);
}

TEST(ColourRegistration, RealKitchenIsTheKinectColourCamera) {
  const fs::path data = fs::path(VARSLAM_SHARED_DIR) / "realdata" / "7scenes_redkitchen";
  if (!fs::exists(data)) GTEST_SKIP() << "real data not found at " << data << " (../shared is absent)";
  std::vector<cv::Mat> grays, depths;
  for (int i = 0; i < 300; i += 30) {
    const std::string stem = cv::format("frame-%06d", i);
    grays.push_back(cv::imread((data / "rgb" / (stem + ".color.jpg")).string(), cv::IMREAD_GRAYSCALE));
    depths.push_back(
        depth_to_metres(cv::imread((data / "depth" / (stem + ".depth.png")).string(), cv::IMREAD_UNCHANGED), 1000.0));
    ASSERT_FALSE(grays.back().empty());
  }
  const ColourRegistration r = estimate_colour_registration(grays, depths, depth_camera());
  EXPECT_TRUE(r.found);
  const PinholeCamera c = r.colour_camera(depth_camera());
  EXPECT_NEAR(c.fx, 530.0, 8.0);
  // Kinect v1's colour camera sits about 2.5 cm from its depth (infrared) camera; at the kitchen's typical 2 m the
  // baseline and the shift together move a pixel by about -7 px.
  EXPECT_LT(r.baseline_x, -0.01);
  EXPECT_GT(r.baseline_x, -0.045);
  EXPECT_NEAR(r.du + c.fx * r.baseline_x / 2.0, -7.0, 3.0);
  EXPECT_NEAR(r.dv, -1.0, 3.0);
}

}  // namespace
}  // namespace varslam
