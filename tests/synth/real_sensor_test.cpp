// The generator's real-sensor effects: disparity steps, smooth depth noise, dark surfaces, lens distortion, rolling
// shutter, the settings it writes, and the effects' keys and their errors.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <set>
#include <sstream>

#include "core/error.hpp"
#include "io/settings.hpp"
#include "synth/real_sensor.hpp"
#include "synth/sensor.hpp"
#include "synth/synth.hpp"

namespace fs = std::filesystem;
using namespace varslam;
using namespace varslam::synth;

namespace {

DepthSensorParams steady_params() {
  DepthSensorParams p;
  p.edge_holes = false;
  p.random_holes = 0;
  return p;
}

// Median |second difference| along rows, in metres (0 where the depth is flat between steps).
double median_second_difference(const cv::Mat1w& raw) {
  std::vector<double> d;
  for (int v = 0; v < raw.rows; v += 3)
    for (int u = 1; u + 1 < raw.cols; u += 3)
      d.push_back(std::abs(raw(v, u - 1) + raw(v, u + 1) - 2.0 * raw(v, u)) / 5000.0);
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

}  // namespace

TEST(RealSensor, DepthComesInDisparityStepsThatGrowWithTheSquareOfTheRange) {
  SplitMix64 rng(3);
  const GaussianTable gauss(5);
  DepthSensorParams p = steady_params();
  p.inverse_depth_step = 0.00285;
  for (const double z : {1.0, 2.0, 3.0}) {
    const cv::Mat1w raw = sense_depth(cv::Mat1f(120, 160, static_cast<float>(z)), p, rng, gauss);
    std::set<int> values(raw.begin(), raw.end());
    ASSERT_GE(values.size(), 3u) << z;
    std::vector<double> gaps;
    for (auto a = values.begin(), b = std::next(a); b != values.end(); ++a, ++b) gaps.push_back((*b - *a) / 5000.0);
    std::sort(gaps.begin(), gaps.end());
    EXPECT_NEAR(gaps[gaps.size() / 2], 0.00285 * z * z, 0.15 * 0.00285 * z * z) << z;
  }
}

TEST(RealSensor, SmoothNoiseKeepsItsSpreadButNeighboursAgree) {
  const GaussianTable gauss(5);
  DepthSensorParams p = steady_params();
  p.depth_factor = 5000;
  const cv::Mat1f plane(240, 320, 2.0f);
  SplitMix64 a(7), b(7);
  const cv::Mat1w white = sense_depth(plane, p, a, gauss);
  p.noise_blur_px = 3;
  const cv::Mat1w smooth = sense_depth(plane, p, b, gauss);
  cv::Scalar m1, s1, m2, s2;
  cv::meanStdDev(white, m1, s1);
  cv::meanStdDev(smooth, m2, s2);
  EXPECT_NEAR(s2[0], s1[0], 0.25 * s1[0]);  // the same sigma per pixel
  EXPECT_LT(median_second_difference(smooth) * 5, median_second_difference(white));
}

TEST(RealSensor, DarkSurfacesLoseDepthAtTheSetRate) {
  SplitMix64 rng(3);
  const GaussianTable gauss(5);
  DepthSensorParams p = steady_params();
  p.dark_dropout = 0.5;
  cv::Mat3f colour(100, 200, cv::Vec3f(0.5f, 0.5f, 0.5f));
  colour.colRange(100, 200).setTo(cv::Vec3f(0.02f, 0.02f, 0.02f));
  const cv::Mat1w raw = sense_depth(cv::Mat1f(100, 200, 2.0f), p, rng, gauss, &colour);
  EXPECT_EQ(cv::countNonZero(raw.colRange(0, 100)), 100 * 100);
  EXPECT_NEAR(cv::countNonZero(raw.colRange(100, 200)) / 10000.0, 0.5, 0.05);
}

TEST(RealSensor, LensDistortionPutsEachPointWhereTheDistortionModelProjectsIt) {
  PinholeCamera cam;
  const double k1 = 0.2312, k2 = -0.7849, k3 = 0.9172;
  const LensDistortion lens(cam, k1, k2, k3);
  // A pinhole image whose pixels hold their own coordinates: after distortion, pixel (u, v) holds the pinhole point
  // that the distortion model sends to (u, v).
  cv::Mat3f coords(cam.height, cam.width);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) coords(v, u) = cv::Vec3f(static_cast<float>(u), static_cast<float>(v), 0);
  cv::Mat3f seen = coords.clone();
  lens.apply(seen);
  const cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  int checked = 0;
  for (const cv::Point p : {cv::Point(40, 30), cv::Point(600, 60), cv::Point(320, 240), cv::Point(100, 420)}) {
    const cv::Vec3f q = seen(p.y, p.x);
    const std::vector<cv::Point3d> ray{{(q[0] - cam.cx) / cam.fx, (q[1] - cam.cy) / cam.fy, 1.0}};
    std::vector<cv::Point2d> projected;
    cv::projectPoints(ray, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, std::vector<double>{k1, k2, 0, 0, k3}, projected);
    EXPECT_NEAR(projected[0].x, p.x, 0.05) << p;
    EXPECT_NEAR(projected[0].y, p.y, 0.05) << p;
    ++checked;
  }
  EXPECT_EQ(checked, 4);
  // The corners move by many pixels (the effect is not negligible), the centre does not.
  EXPECT_GT(std::abs(seen(30, 40)[0] - 40.0f), 5.0f);
  EXPECT_NEAR(seen(240, 320)[0], 320.0f, 0.5f);
}

TEST(RealSensor, RollingShutterShiftsEachRowByTheCameraMotionAtItsTime) {
  PinholeCamera cam;
  cv::Mat3f coords(cam.height, cam.width);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) coords(v, u) = cv::Vec3f(static_cast<float>(u), static_cast<float>(v), 0);
  const cv::Mat1f depth(cam.height, cam.width, 2.0f);
  // The camera slides along +x by 2 cm from the first row to the last, centred on the rendered pose.
  cv::Mat3f seen = coords.clone();
  apply_rolling_shutter(seen, depth, cam, Eigen::Isometry3d::Identity(), [&](int row) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation().x() = 0.02 * (row / (cam.height - 1.0) - 0.5);
    return T;
  });
  const double shift_px = 0.02 * cam.fx / 2.0;  // 2 cm at 2 m
  EXPECT_NEAR(seen(0, 320)[0] - 320.0f, -shift_px / 2, 0.05);
  EXPECT_NEAR(seen(cam.height - 1, 320)[0] - 320.0f, shift_px / 2, 0.05);
  EXPECT_NEAR(seen(240, 320)[0], 320.0f, 0.05);
}

TEST(RealSensor, TheSequenceStatesTheWrongIntrinsicsAndStampsTheDepthLater) {
  SynthConfig cfg;
  cfg.scenario = "static";
  cfg.seconds = 0.3;
  cfg.fps = 10;
  cfg.preview = false;
  cfg.real = kinect1_sensor();
  const fs::path out = fs::temp_directory_path() / "varslam_real_sensor_test";
  fs::remove_all(out);
  generate(cfg, out);
  const Settings s = load_settings(out / "settings.yaml");
  const PinholeCamera truth;
  EXPECT_NEAR(s.camera.fx, truth.fx * 1.005, 1e-6);
  EXPECT_NEAR(s.camera.cx, truth.cx + 2, 1e-6);
  EXPECT_DOUBLE_EQ(s.camera.k1, 0.2312);
  std::ifstream rgb(out / "rgb.txt"), depth(out / "depth.txt");
  std::string a, b;
  std::vector<double> rgb_t, depth_t;
  while (std::getline(rgb, a))
    if (!a.empty() && a[0] != '#') rgb_t.push_back(std::stod(a));
  while (std::getline(depth, b))
    if (!b.empty() && b[0] != '#') depth_t.push_back(std::stod(b));
  ASSERT_EQ(rgb_t.size(), 3u);
  ASSERT_EQ(depth_t.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(depth_t[i] - rgb_t[i], 0.016, 1e-6);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_TRUE(fs::exists(out / "depth" / (fmt::format("{:.6f}", depth_t[i]) + ".png")));
  std::ifstream scenario(out / "scenario.json");
  const auto j = nlohmann::json::parse(scenario);
  EXPECT_DOUBLE_EQ(j["sensor"]["real"]["rolling_shutter_s"].get<double>(), 0.025);
  fs::remove_all(out);
}

TEST(RealSensor, EffectsAreSetByNameAndBadOnesAreNamed) {
  RealSensorEffects e;
  set_sensor_effect(e, "rolling_shutter_s", "0.03");
  EXPECT_DOUBLE_EQ(e.rolling_shutter_s, 0.03);
  set_sensor_effect(e, "depth_offset_m", "0.01,0,-0.002");
  EXPECT_DOUBLE_EQ(e.depth_offset_m.z(), -0.002);
  set_sensor_effect(e, "distortion_in_settings", "false");
  EXPECT_FALSE(e.distortion_in_settings);
  const auto message = [&](const std::string& k, const std::string& v) {
    try {
      set_sensor_effect(e, k, v);
    } catch (const InputError& err) {
      return std::string(err.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("rolling_shuter_s", "0.03").find("unknown sensor effect 'rolling_shuter_s'"), std::string::npos);
  EXPECT_NE(message("rolling_shuter_s", "0.03").find("rolling_shutter_s"), std::string::npos);  // lists the known
  EXPECT_NE(message("depth_scale", "2").find("outside"), std::string::npos);
  EXPECT_NE(message("k1", "0.2x").find("not a number"), std::string::npos);
  EXPECT_NE(message("depth_offset_m", "0.01,0").find("x,y,z"), std::string::npos);
  EXPECT_NE(message("distortion_in_settings", "yes").find("true or false"), std::string::npos);
  EXPECT_EQ(describe(e)["rolling_shutter_s"].get<double>(), 0.03);
}
