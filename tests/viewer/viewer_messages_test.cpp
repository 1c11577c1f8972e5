#include "viewer/viewer_messages.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <opencv2/imgcodecs.hpp>

namespace varslam::viewer {
namespace {

std::vector<unsigned char> unbase64(const std::string& s) {
  std::vector<unsigned char> out;
  int val = 0, bits = -8;
  for (char ch : s) {
    const char* a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const char* p = std::strchr(a, ch);
    if (ch == '=' || !p) break;
    val = (val << 6) + static_cast<int>(p - a);
    bits += 6;
    if (bits >= 0) {
      out.push_back(static_cast<unsigned char>((val >> bits) & 0xFF));
      bits -= 8;
    }
  }
  return out;
}

std::vector<float> floats_of(const std::string& b64) {
  const auto bytes = unbase64(b64);
  std::vector<float> f(bytes.size() / 4);
  std::memcpy(f.data(), bytes.data(), f.size() * 4);
  return f;
}

TEST(ViewerMessages, Base64OfKnownStrings) {
  EXPECT_EQ(base64("", 0), "");
  EXPECT_EQ(base64("f", 1), "Zg==");
  EXPECT_EQ(base64("fo", 2), "Zm8=");
  EXPECT_EQ(base64("foo", 3), "Zm9v");
  EXPECT_EQ(base64("foobar", 6), "Zm9vYmFy");
  const unsigned char high[] = {0xff, 0xfe, 0x00};
  EXPECT_EQ(base64(high, 3), "//4A");
}

TEST(ViewerMessages, FrameMessageCarriesPoseMarksPeopleAndAScaledJpeg) {
  FrameView f;
  f.index = 12;
  f.state = slam::TrackState::Ok;
  f.keypoints = 3;
  f.T_wc = Eigen::Isometry3d(Eigen::Translation3d(1, 2, 3));
  f.marks = {{100, 50, 1}, {200, 60, 2 | kDepthEdgeBit}, {300, 70, 3}};
  f.people = {{cv::Rect(640, 0, 320, 480), 1.5f, 0.3f}};
  const cv::Mat image(960, 1280, CV_8UC3, cv::Scalar(10, 20, 30));
  const nlohmann::json j = frame_message(f, image, 640);
  EXPECT_EQ(j["index"], 12);
  EXPECT_EQ(j["state"], "tracking");
  EXPECT_EQ(j["T_wc"].size(), 12u);
  EXPECT_FLOAT_EQ(j["T_wc"][9].get<float>(), 1.0f);
  EXPECT_EQ(j["image"]["width"], 640);  // 1280 wide: halved
  const auto jpeg = unbase64(j["image"]["jpeg"].get<std::string>());
  const cv::Mat decoded = cv::imdecode(jpeg, cv::IMREAD_COLOR);
  EXPECT_EQ(decoded.cols, 640);
  EXPECT_EQ(decoded.rows, 480);
  const auto marks = floats_of(j["marks"]);
  ASSERT_EQ(marks.size(), 9u);
  EXPECT_FLOAT_EQ(marks[0], 50.0f);  // pixel positions scaled with the image
  EXPECT_FLOAT_EQ(marks[5], static_cast<float>(2 | kDepthEdgeBit));
  EXPECT_DOUBLE_EQ(j["people"][0]["x"].get<double>(), 320.0);
  EXPECT_FLOAT_EQ(j["people"][0]["depth_m"].get<float>(), 1.5f);
}

TEST(ViewerMessages, MapMessageCarriesEveryKeyframePointAndEdge) {
  MapView m;
  for (int k = 0; k < 3; ++k) m.keyframes.push_back({k, Eigen::Isometry3d(Eigen::Translation3d(k, 0, 0))});
  m.points = {{Eigen::Vector3f(1, 2, 3), 0, 0.0f}, {Eigen::Vector3f(4, 5, 6), 2, 0.5f}};
  m.covisibility = {{0, 1}, {1, 2}};
  m.spanning_tree = {{1, 0}};
  m.live = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0)};
  const nlohmann::json j = map_message(m);
  EXPECT_EQ(j["keyframe_count"], 3);
  const auto kfs = floats_of(j["keyframes"]);
  ASSERT_EQ(kfs.size(), 3u * 13);
  EXPECT_FLOAT_EQ(kfs[13 * 2], 2.0f);       // id
  EXPECT_FLOAT_EQ(kfs[13 * 2 + 10], 2.0f);  // x of its translation
  const auto pts = floats_of(j["points"]);
  ASSERT_EQ(pts.size(), 10u);
  EXPECT_FLOAT_EQ(pts[5], 4.0f);
  EXPECT_FLOAT_EQ(pts[9], 0.5f);
  EXPECT_EQ(unbase64(j["covisibility"]).size(), 4u * 4);
  EXPECT_EQ(floats_of(j["live"]).size(), 6u);
}

TEST(ViewerMessages, GroundTruthIsBroughtIntoTheMapFrame) {
  Trajectory gt, est;
  const Eigen::Isometry3d offset(Eigen::Translation3d(5, 0, 0) * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  for (int i = 0; i < 20; ++i) {
    const Eigen::Isometry3d T(Eigen::Translation3d(0.1 * i, 0.05 * i * i * 0.1, 0.02 * i));
    est.push_back({i * 0.1, T});
    gt.push_back({i * 0.1, offset * T});
  }
  const auto in_map = groundtruth_in_map_frame(gt, est);
  ASSERT_EQ(in_map.size(), gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) EXPECT_LT((in_map[i] - est[i].T_wc.translation()).norm(), 1e-6);
  EXPECT_TRUE(groundtruth_in_map_frame(gt, {}).empty());
}

// The dense layer's region: int16 offsets from the region's corner in steps of `unit`, colours as bytes.
TEST(ViewerMessages, DenseRegionMessageCarriesEveryPointWithinHalfAUnit) {
  DenseRegionView r;
  r.key = "1,-2,3";
  r.size = 0.64;
  r.origin = Eigen::Vector3d(0.64, -1.28, 1.92);
  r.cell = 0.04;
  r.points.push_back({Eigen::Vector3f(0.7f, -1.2f, 2.0f), {10, 20, 30}});
  r.points.push_back({Eigen::Vector3f(1.3f, -0.63f, 2.57f), {255, 0, 128}});  // just past the far side
  const nlohmann::json j = dense_region_message(r);
  EXPECT_EQ(j["key"], "1,-2,3");
  EXPECT_EQ(j["count"], 2);
  EXPECT_DOUBLE_EQ(j["unit"].get<double>(), 0.64 / 8192);
  EXPECT_DOUBLE_EQ(j["cell"].get<double>(), 0.04);
  const std::vector<unsigned char> xyz = unbase64(j["xyz"]), rgb = unbase64(j["rgb"]);
  ASSERT_EQ(xyz.size(), 2u * 3 * sizeof(std::int16_t));
  ASSERT_EQ(rgb.size(), 6u);
  std::vector<std::int16_t> q(6);
  std::memcpy(q.data(), xyz.data(), xyz.size());
  const double unit = j["unit"];
  for (std::size_t i = 0; i < 2; ++i)
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(j["origin"][a].get<double>() + q[i * 3 + static_cast<std::size_t>(a)] * unit,
                  r.points[i].position[a], unit / 2 + 1e-6);
  EXPECT_EQ(std::vector<unsigned char>(rgb.begin(), rgb.end()),
            (std::vector<unsigned char>{10, 20, 30, 255, 0, 128}));
  r.points.clear();  // a region emptied: the message says so
  EXPECT_EQ(dense_region_message(r)["count"], 0);
}

}  // namespace
}  // namespace varslam::viewer
