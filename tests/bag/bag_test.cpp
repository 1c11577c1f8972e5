// ROS 1 bags as input: the image codecs, the choice of topics, a bag written from a synthetic sequence that gives
// the folder's trajectory byte for byte (raw, lossless compressed, RealSense layout), and bad bags named clearly.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "bag/bag_dataset.hpp"
#include "bag/bag_from_folder.hpp"
#include "bag/topic_choice.hpp"
#include "core/error.hpp"
#include "io/ros_image_codec.hpp"
#include "io/trajectory_io.hpp"
#include "file_text.hpp"
#include "slam/e2e_support.hpp"
#ifdef VARSLAM_HAVE_ROSBAG
#include "bagfile/bag_file.hpp"
#endif

namespace varslam::bag {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

template <typename Fn>
std::string error_of(Fn fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

using test::slurp;

// --- codecs: plain bytes, no bag needed ---------------------------------------------------------------------------

TEST(ImageCodec, RawEncodingsDecodeToBgrAndDepth) {
  const std::vector<std::uint8_t> rgb = {255, 0, 0, 0, 255, 0};  // red, green
  const cv::Mat bgr = ros_image::decode_raw_image("rgb8", 2, 1, 6, false, rgb.data(), rgb.size(), "t");
  ASSERT_EQ(bgr.type(), CV_8UC3);
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 1), cv::Vec3b(0, 255, 0));
  const std::vector<std::uint8_t> d16 = {0x10, 0x27, 0, 0};  // 10000 little-endian, then 0
  const cv::Mat depth = ros_image::decode_raw_image("16UC1", 2, 1, 4, false, d16.data(), d16.size(), "t");
  ASSERT_EQ(depth.type(), CV_16UC1);
  EXPECT_EQ(depth.at<std::uint16_t>(0, 0), 10000);
  const std::vector<std::uint8_t> d16be = {0x27, 0x10};
  EXPECT_EQ(ros_image::decode_raw_image("mono16", 1, 1, 2, true, d16be.data(), 2, "t").at<std::uint16_t>(0, 0), 10000);
  // Rows padded beyond width * bytes per pixel (step) are read row by row.
  // A step that is not a multiple of the pixel size (found by fuzzing: OpenCV refuses it as a matrix step).
  const std::vector<std::uint8_t> odd = {0x10, 0x27, 99, 0x20, 0x4e, 99};
  const cv::Mat odd_depth = ros_image::decode_raw_image("16UC1", 1, 2, 3, false, odd.data(), odd.size(), "t");
  EXPECT_EQ(odd_depth.at<std::uint16_t>(1, 0), 20000);
  const std::vector<std::uint8_t> padded = {7, 99, 8, 99};
  const cv::Mat mono = ros_image::decode_raw_image("mono8", 1, 2, 2, false, padded.data(), padded.size(), "t");
  EXPECT_EQ(mono.at<std::uint8_t>(1, 0), 8);
}

TEST(ImageCodec, BrokenRawImagesAreNamedErrors) {
  const std::vector<std::uint8_t> few(10, 0);
  EXPECT_THAT(
      error_of([&] { ros_image::decode_raw_image("yuv422", 2, 2, 4, false, few.data(), few.size(), "b:/t 3"); }),
      AllOf(HasSubstr("b:/t 3"), HasSubstr("'yuv422' is not supported"), HasSubstr("rgb8")));
  EXPECT_THAT(error_of([&] { ros_image::decode_raw_image("bgr8", 4, 4, 12, false, few.data(), few.size(), "b:/t"); }),
              AllOf(HasSubstr("needs 48 bytes"), HasSubstr("holds 10")));
  EXPECT_THAT(error_of([&] { ros_image::decode_raw_image("bgr8", 4, 1, 4, false, few.data(), few.size(), "b:/t"); }),
              HasSubstr("step 4"));
}

TEST(ImageCodec, CompressedDepthRoundTripsAndBadDataIsNamed) {
  cv::Mat d(3, 4, CV_16UC1);
  for (int i = 0; i < 12; ++i) d.at<std::uint16_t>(i / 4, i % 4) = static_cast<std::uint16_t>(i * 1000);
  const auto bytes = ros_image::encode_compressed_depth(d);
  const cv::Mat back =
      ros_image::decode_compressed_image("16UC1; compressedDepth png", bytes.data(), bytes.size(), "t");
  ASSERT_EQ(back.type(), CV_16UC1);
  EXPECT_EQ(cv::norm(back, d, cv::NORM_INF), 0.0);
  // 32FC1 compressedDepth: inverse depth v = a / z + b.
  std::vector<std::uint8_t> inv = bytes;
  const float a = 1000.0f, b = 0.0f;
  std::memcpy(inv.data() + 4, &a, 4);
  std::memcpy(inv.data() + 8, &b, 4);
  const cv::Mat z = ros_image::decode_compressed_image("32FC1; compressedDepth", inv.data(), inv.size(), "t");
  EXPECT_FLOAT_EQ(z.at<float>(0, 1), 1.0f);  // 1000 / 1000
  EXPECT_FLOAT_EQ(z.at<float>(0, 0), 0.0f);  // 0 = no depth
  const std::vector<std::uint8_t> junk(40, 7);
  EXPECT_THAT(
      error_of([&] { ros_image::decode_compressed_image("16UC1; compressedDepth", junk.data(), 40, "b:/d 1"); }),
      AllOf(HasSubstr("b:/d 1"), HasSubstr("holds no PNG")));
  EXPECT_THAT(error_of([&] { ros_image::decode_compressed_image("jpeg", junk.data(), 40, "b:/c 1"); }),
              HasSubstr("not PNG or JPEG"));
}

// --- topic choice --------------------------------------------------------------------------------------------------

const char* kImg = "sensor_msgs/Image";
const char* kCmp = "sensor_msgs/CompressedImage";
const char* kInfo = "sensor_msgs/CameraInfo";

TEST(TopicChoice, FindsTheTumRealSenseAndOpenLorisLayouts) {
  const std::vector<TopicEntry> tum = {
      {"/camera/depth/camera_info", kInfo, 1},         {"/camera/depth/image", kImg, 9},
      {"/camera/rgb/camera_info", kInfo, 1},           {"/camera/rgb/image_color", kImg, 9},
      {"/camera/rgb/image_color/compressed", kCmp, 9}, {"/tf", "tf2_msgs/TFMessage", 9}};
  const ChosenTopics t = choose_topics("b", tum, "", "", "");
  EXPECT_EQ(t.rgb, "/camera/rgb/image_color");
  EXPECT_EQ(t.depth, "/camera/depth/image");
  EXPECT_EQ(t.info, "/camera/rgb/camera_info");
  const std::vector<TopicEntry> rs = {{"/device_0/sensor_0/Depth_0/image/data", kImg, 9},
                                      {"/device_0/sensor_0/Depth_0/info/camera_info", kInfo, 1},
                                      {"/device_0/sensor_0/Infrared_1/image/data", kImg, 9},
                                      {"/device_0/sensor_0/option/Depth Units/value", "std_msgs/Float32", 1},
                                      {"/device_0/sensor_1/Color_0/image/data", kImg, 9},
                                      {"/device_0/sensor_1/Color_0/info/camera_info", kInfo, 1}};
  const ChosenTopics r = choose_topics("b", rs, "", "", "");
  EXPECT_EQ(r.rgb, "/device_0/sensor_1/Color_0/image/data");
  EXPECT_EQ(r.depth, "/device_0/sensor_0/Depth_0/image/data");
  EXPECT_EQ(r.info, "/device_0/sensor_1/Color_0/info/camera_info");
  EXPECT_EQ(r.depth_units, "/device_0/sensor_0/option/Depth Units/value");
  const std::vector<TopicEntry> lo = {{"/d400/color/image_raw", kImg, 9},
                                      {"/d400/color/camera_info", kInfo, 1},
                                      {"/d400/depth/image_raw", kImg, 9},
                                      {"/d400/aligned_depth_to_color/image_raw", kImg, 9},
                                      {"/d400/depth/camera_info", kInfo, 1}};
  const ChosenTopics l = choose_topics("b", lo, "", "", "");
  EXPECT_EQ(l.rgb, "/d400/color/image_raw");
  EXPECT_EQ(l.depth, "/d400/aligned_depth_to_color/image_raw");
  EXPECT_EQ(l.info, "/d400/color/camera_info");
}

TEST(TopicChoice, AmbiguityMissingTopicsAndWrongTypesAreNamed) {
  const std::vector<TopicEntry> two = {
      {"/left/color/image_raw", kImg, 9}, {"/right/color/image_raw", kImg, 9}, {"/left/depth/image_raw", kImg, 9}};
  EXPECT_THAT(
      error_of([&] { choose_topics("x.bag", two, "", "", ""); }),
      AllOf(HasSubstr("x.bag"), HasSubstr("/left/color/image_raw, /right/color/image_raw"), HasSubstr("--topic-rgb")));
  EXPECT_EQ(choose_topics("x.bag", two, "/right/color/image_raw", "", "").rgb, "/right/color/image_raw");
  const std::vector<TopicEntry> none = {{"/imu", "sensor_msgs/Imu", 5}, {"/tf", "tf2_msgs/TFMessage", 5}};
  EXPECT_THAT(error_of([&] { choose_topics("x.bag", none, "", "", ""); }),
              AllOf(HasSubstr("no image topic"), HasSubstr("/imu (sensor_msgs/Imu, 5 messages)"), HasSubstr("/tf")));
  EXPECT_THAT(error_of([&] { choose_topics("x.bag", two, "/nope", "", ""); }),
              AllOf(HasSubstr("--topic-rgb /nope is not in the bag"), HasSubstr("/left/depth/image_raw")));
  EXPECT_THAT(error_of([&] { choose_topics("x.bag", none, "/imu", "", ""); }),
              HasSubstr("--topic-rgb /imu is a sensor_msgs/Imu, not an image topic"));
  const std::vector<TopicEntry> colour_only = {{"/camera/rgb/image_color", kImg, 9}};
  EXPECT_THAT(error_of([&] { choose_topics("x.bag", colour_only, "", "", ""); }),
              AllOf(HasSubstr("no depth image topic"), HasSubstr("--topic-depth")));
}

#ifdef VARSLAM_HAVE_ROSBAG

// --- bags written from a synthetic sequence -----------------------------------------------------------------------

const fs::path& sequence() {
  static const fs::path dir = slam::e2e::pipeline_walking_sequence();
  return dir;
}

fs::path temp(const std::string& name) {
  return fs::temp_directory_path() / ("varslam_bag_" + name + "_" + std::to_string(::getpid()));
}

// Bags of raw frames are large: each test's folders go when the test process ends.
struct RemoveTempFolders : ::testing::Environment {
  void TearDown() override {
    const std::string suffix = "_" + std::to_string(::getpid());
    for (const auto& e : fs::directory_iterator(fs::temp_directory_path())) {
      const std::string n = e.path().filename().string();
      if (n.rfind("varslam_bag_", 0) == 0 && n.size() > suffix.size() &&
          n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0)
        fs::remove_all(e.path());
    }
  }
};
const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new RemoveTempFolders);

fs::path write_bag(const std::string& name, BagLayout layout, BagImages images) {
  const Settings settings = settings_for_dataset(sequence(), std::nullopt);
  const auto ds = open_dataset(sequence(), settings);
  const fs::path out = temp(name) / (name + ".bag");
  fs::remove_all(out.parent_path());
  BagWriteOptions o;
  o.layout = layout;
  o.images = images;
  write_bag_from_dataset(*ds, settings, out, o);
  return out;
}

std::string trajectory_of_bag(const fs::path& bag, const std::string& name, const BagTopics& topics = {}) {
  Settings settings = settings_for_bag(bag, std::nullopt, topics);
  apply_setting_overrides(settings, {"semantic.detector=none"});
  const auto ds = open_bag_dataset(bag, settings, topics);
  run::RunOptions ro;
  ro.progress = false;
  const fs::path out = temp(name + "_run");
  run::run_slam(*ds, settings, ro, out);
  return slurp(out / "CameraTrajectory.txt");
}

std::string trajectory_of_folder() {
  static const std::string t = [] {
    const fs::path out = temp("folder_run");
    slam::e2e::run_on(sequence(), out, RunMode::Deterministic, SIZE_MAX, {"semantic.detector=none"});
    return slurp(out / "CameraTrajectory.txt");
  }();
  return t;
}

TEST(BagInput, RawAndLosslessCompressedBagsGiveTheFolderTrajectoryByteForByte) {
  const std::string folder = trajectory_of_folder();
  ASSERT_GT(std::count(folder.begin(), folder.end(), '\n'), 50);
  EXPECT_EQ(trajectory_of_bag(write_bag("raw", BagLayout::Tum, BagImages::Raw), "raw"), folder);
  EXPECT_EQ(trajectory_of_bag(write_bag("png", BagLayout::Tum, BagImages::Png), "png"), folder);
}

TEST(BagInput, RealSenseLayoutIsReadWithItsCameraInfoAndDepthUnit) {
  const fs::path bag = write_bag("rs", BagLayout::RealSense, BagImages::Raw);
  const Settings folder = settings_for_dataset(sequence(), std::nullopt);
  const Settings s = settings_for_bag(bag, std::nullopt, {});
  EXPECT_EQ(s.camera.fx, folder.camera.fx);
  EXPECT_EQ(s.camera.cy, folder.camera.cy);
  EXPECT_EQ(s.camera.width, folder.camera.width);
  EXPECT_NEAR(s.depth_factor, folder.depth_factor, 1e-3);  // from "Depth Units" (a float32)
  BagTopics with_gt;
  with_gt.gt_frame = "kinect";
  const auto ds = open_bag_dataset(bag, s, with_gt);
  const auto fds = open_dataset(sequence(), folder);
  ASSERT_EQ(ds->size(), fds->size());
  ASSERT_TRUE(ds->groundtruth());
  EXPECT_EQ(read_tum_trajectory(*ds->groundtruth()).size(), read_tum_trajectory(*fds->groundtruth()).size());
  const RgbdFrame a = ds->load(7), b = fds->load(7);
  EXPECT_EQ(a.timestamp, b.timestamp);
  EXPECT_EQ(cv::norm(a.bgr, b.bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.depth, b.depth, cv::NORM_INF), 0.0);  // the same float scale per raw step
  // The infrared stream beside them is neither colour nor depth.
  EXPECT_EQ(trajectory_of_bag(bag, "rs"), trajectory_of_folder());
}

TEST(BagInput, TheSettingsFileWinsOverCameraInfo) {
  const fs::path bag = write_bag("settings_wins", BagLayout::Tum, BagImages::Raw);
  const fs::path yaml = temp("settings_wins") / "cam.yaml";
  Settings other = settings_for_dataset(sequence(), std::nullopt);
  other.camera.fx = 600;
  other.root["camera"]["fx"] = 600;
  save_settings(other, yaml);
  EXPECT_EQ(settings_for_bag(bag, yaml, {}).camera.fx, 600);
  EXPECT_EQ(settings_for_bag(bag, std::nullopt, {}).camera.fx,
            settings_for_dataset(sequence(), std::nullopt).camera.fx);
}

// --- bad bags --------------------------------------------------------------------------------------------------------

TEST(BadBag, NotABagTruncatedAndUnindexedAreNamed) {
  const fs::path dir = temp("bad");
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "text.bag") << "timestamp x y z\n";
  EXPECT_THAT(error_of([&] { settings_for_bag(dir / "text.bag", std::nullopt, {}); }),
              AllOf(HasSubstr("text.bag"), HasSubstr("not a ROS bag")));
  EXPECT_THAT(error_of([&] { settings_for_bag(dir / "missing.bag", std::nullopt, {}); }), HasSubstr("does not exist"));
  // A recording cut off before its index was written.
  const fs::path good = write_bag("for_cut", BagLayout::Tum, BagImages::Png);
  const std::string bytes = slurp(good);
  std::ofstream(dir / "cut.bag", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_THAT(error_of([&] { settings_for_bag(dir / "cut.bag", std::nullopt, {}); }),
              AllOf(HasSubstr("cut.bag"), HasSubstr("rosbag reindex")));
}

TEST(BadBag, NoImagesUnknownEncodingAndMismatchedDepthAreNamed) {
  const fs::path dir = temp("bad2");
  fs::remove_all(dir);
  fs::create_directories(dir);
  {
    bagfile::Writer w((dir / "tf_only.bag").string());
    w.transform("/tf", {1.0, "world", "kinect", 0, 0, 0, 0, 0, 0, 1});
  }
  EXPECT_THAT(error_of([&] { settings_for_bag(dir / "tf_only.bag", std::nullopt, {}); }),
              AllOf(HasSubstr("no image topic"), HasSubstr("/tf (tf2_msgs/TFMessage, 1 messages)")));
  bagfile::CameraInfo info;
  info.width = 8;
  info.height = 6;
  info.fx = info.fy = 10;
  info.cx = 4;
  info.cy = 3;
  {
    bagfile::Writer w((dir / "odd.bag").string());
    w.camera_info("/camera/rgb/camera_info", 1.0, info);
    for (int i = 0; i < 3; ++i) {
      w.image("/camera/rgb/image_color", 1.0 + i / 30.0, "c", cv::Mat(6, 8, CV_8UC3, cv::Scalar(1, 2, 3)), "bgr8");
      w.image("/camera/depth/image", 1.0 + i / 30.0, "d", cv::Mat(3, 4, CV_32FC1, cv::Scalar(1.0f)), "32FC1");
    }
  }
  const Settings s = settings_for_bag(dir / "odd.bag", std::nullopt, {});
  EXPECT_EQ(s.camera.width, 8);
  const auto ds = open_bag_dataset(dir / "odd.bag", s, {});
  EXPECT_THAT(error_of([&] { ds->load(0); }), AllOf(HasSubstr("odd.bag:/camera/depth/image message 0"),
                                                    HasSubstr("depth image is 4x3 but colour is 8x6")));
  BagTopics body;
  body.gt_frame = "body";
  EXPECT_THAT(error_of([&] { open_bag_dataset(dir / "odd.bag", s, body); }),
              AllOf(HasSubstr("--gt-frame body"), HasSubstr("no transform")));
}

#endif

}  // namespace
}  // namespace varslam::bag
