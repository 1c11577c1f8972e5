#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.hpp"
#include "semantic/detector.hpp"
#include "semantic/filter_stages_image.hpp"
#include "semantic/keypoint_filter.hpp"
#include "test_data.hpp"

namespace varslam::semantic {
namespace {
namespace fs = std::filesystem;

DetectorConfig yolo_config() {
  DetectorConfig cfg;
  cfg.source = "yolo";
  cfg.model_dir = testdata::models_dir();
  return cfg;
}

void expect_valid_person_boxes(const Detections& dets, const cv::Mat& img, double t, float min_score) {
  for (const auto& d : dets) {
    EXPECT_EQ(d.label, "person");
    EXPECT_DOUBLE_EQ(d.timestamp, t);
    EXPECT_GE(d.score, min_score);
    EXPECT_GT(d.box.width, 4.f);
    EXPECT_GT(d.box.height, 4.f);
    EXPECT_GE(d.box.x, 0.f);
    EXPECT_GE(d.box.y, 0.f);
    EXPECT_LE(d.box.x + d.box.width, static_cast<float>(img.cols) + 0.5f);
    EXPECT_LE(d.box.y + d.box.height, static_cast<float>(img.rows) + 0.5f);
  }
}

int count_upright(const Detections& dets) {
  int n = 0;
  for (const auto& d : dets) n += d.box.height > d.box.width ? 1 : 0;
  return n;
}

TEST(YoloDetector, FindsPeopleInRealVideo) {
  if (!testdata::have_yolo() || !testdata::have_video())
    GTEST_SKIP() << "needs " << testdata::models_dir() << " (VARSLAM_SHARED_DIR) and " << testdata::vtest_video();
  auto det = make_detector(yolo_config());
  cv::VideoCapture cap(testdata::vtest_video().string());
  cv::Mat frame;
  int frames = 0, people = 0, upright = 0;
  for (int i = 0; i < 120 && cap.read(frame); ++i) {
    if (i % 40 != 0) continue;  // frames 0, 40, 80: several pedestrians each
    const Detections dets = det->detect(frame, i / 10.0);
    expect_valid_person_boxes(dets, frame, i / 10.0, 0.3f);
    EXPECT_GE(dets.size(), 2u) << "frame " << i;
    people += static_cast<int>(dets.size());
    upright += count_upright(dets);
    ++frames;
  }
  ASSERT_EQ(frames, 3);
  EXPECT_GE(people, 8);
  EXPECT_GE(upright, people * 3 / 4) << "pedestrian boxes are taller than wide";
}

TEST(YoloDetector, BodyModelLabelIsAliasedToPerson) {
  if (!fs::exists(testdata::models_dir() / "yolo-fastest-1.1_body.weights") || !testdata::have_video())
    GTEST_SKIP() << "needs the body model in " << testdata::models_dir() << " and " << testdata::vtest_video();
  DetectorConfig cfg = yolo_config();
  cfg.model = "yolo-fastest-1.1_body";
  const auto files = resolve_yolo_files(cfg);
  EXPECT_EQ(files.names.filename(), "body.names");
  auto det = make_detector(cfg);
  const cv::Mat frame = testdata::vtest_frame(0);
  const Detections dets = det->detect(frame, 0.0);
  EXPECT_GE(dets.size(), 2u);
  expect_valid_person_boxes(dets, frame, 0.0, 0.3f);

  cfg.label_aliases.clear();  // without the alias the body class is not a "person": nothing to keep
  EXPECT_THROW(make_detector(cfg), InputError);
}

TEST(YoloDetector, ClassFilterKeepsOnlyConfiguredLabels) {
  if (!testdata::have_yolo() || !testdata::have_video()) GTEST_SKIP() << "needs the shared model and vtest.avi";
  DetectorConfig cfg = yolo_config();
  cfg.model = "yolo-fastest-1.1-xl";  // the 80-class model (the default body model knows only a person)
  cfg.classes = {"person", "handbag", "car"};
  auto det = make_detector(cfg);
  const cv::Mat frame = testdata::vtest_frame(0);
  for (const auto& d : det->detect(frame, 0.0))
    EXPECT_TRUE(d.label == "person" || d.label == "handbag" || d.label == "car") << d.label;
  cfg.classes = {"giraffe"};
  auto giraffes = make_detector(cfg);
  EXPECT_TRUE(giraffes->detect(frame, 0.0).empty());
}

TEST(Detector, MissingModelFileIsAnInputErrorNamingTheFile) {
  DetectorConfig cfg;
  cfg.source = "yolo";
  cfg.model_cfg = "/nonexistent/dir/my-yolov4.cfg";
  cfg.model_weights = "/nonexistent/dir/my-yolov4.weights";
  try {
    make_detector(cfg);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("/nonexistent/dir/my-yolov4.weights"), std::string::npos) << msg;
    EXPECT_NE(msg.find("hog"), std::string::npos) << "should name the sources that need no model: " << msg;
    EXPECT_NE(msg.find("boxes"), std::string::npos) << msg;
  }
}

TEST(Detector, MissingCfgNextToExistingWeightsIsNamed) {
  const fs::path dir = fs::path(::testing::TempDir()) / "varslam_semantic_missing_cfg";
  fs::create_directories(dir);
  std::ofstream(dir / "net.weights") << "x";
  DetectorConfig cfg;
  cfg.source = "yolo";
  cfg.model_weights = dir / "net.weights";
  cfg.model_cfg = dir / "net.cfg";
  try {
    make_detector(cfg);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "net.cfg").string()), std::string::npos) << e.what();
  }
}

TEST(Detector, DefaultModelSearchHonoursVarslamModelsEnv) {
  const fs::path dir = fs::path(::testing::TempDir()) / "varslam_semantic_env_models";
  fs::create_directories(dir);
  ::setenv("VARSLAM_MODELS", dir.c_str(), 1);
  const auto dirs = model_search_dirs();
  ::unsetenv("VARSLAM_MODELS");
  ASSERT_FALSE(dirs.empty());
  EXPECT_EQ(dirs.front(), dir);
  // An empty env models dir: the default preset is missing and the error says where it looked.
  ::setenv("VARSLAM_MODELS", dir.c_str(), 1);
  DetectorConfig cfg;
  cfg.source = "yolo";
  try {
    resolve_yolo_files(cfg);
    if (!fs::exists("models/yolo-fastest-1.1_body.weights") &&
        !fs::exists("../shared/models/yolo-fastest-1.1_body.weights"))
      ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("yolo-fastest-1.1_body.weights"), std::string::npos) << e.what();
  }
  ::unsetenv("VARSLAM_MODELS");
}

TEST(Detector, UnknownSourceIsAnInputError) {
  DetectorConfig cfg;
  cfg.source = "sam";
  EXPECT_THROW(make_detector(cfg), InputError);
}

TEST(Detector, NoneFindsNothing) {
  auto det = make_detector(DetectorConfig{});
  EXPECT_EQ(det->name(), "none");
  EXPECT_TRUE(det->detect(cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(128)), 1.0).empty());
}

TEST(Detector, BoxesSourceReplaysTheFileByTimestamp) {
  const fs::path file = fs::path(::testing::TempDir()) / "varslam_semantic_boxes.txt";
  std::ofstream(file) << "# t label score x y w h\n"
                         "1.000 person 0.9 10 20 30 40\n"
                         "1.000 chair 0.8 50 50 10 10\n"
                         "2.000 body 0.7 5 6 7 8\n";
  DetectorConfig cfg;
  cfg.source = "boxes";
  cfg.boxes_file = file;
  auto det = make_detector(cfg);
  const cv::Mat img(100, 100, CV_8UC3);
  const Detections at1 = det->detect(img, 1.01);
  ASSERT_EQ(at1.size(), 1u);  // the chair is not a configured class
  EXPECT_EQ(at1[0].box, cv::Rect2f(10, 20, 30, 40));
  const Detections at2 = det->detect(img, 2.0);
  ASSERT_EQ(at2.size(), 1u);
  EXPECT_EQ(at2[0].label, "person");  // body -> person alias
  EXPECT_TRUE(det->detect(img, 1.5).empty());

  cfg.boxes_file = "/nonexistent/boxes.txt";
  try {
    make_detector(cfg);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/boxes.txt"), std::string::npos);
  }
}

TEST(HogDetector, RunsOnARealFrame) {
  if (!testdata::have_video()) GTEST_SKIP() << "needs " << testdata::vtest_video();
  DetectorConfig cfg;
  cfg.source = "hog";
  cfg.conf_threshold = 0.0f;
  auto det = make_detector(cfg);
  EXPECT_EQ(det->name(), "hog");
  const cv::Mat frame = testdata::vtest_frame(0);
  ASSERT_FALSE(frame.empty());
  const Detections dets = det->detect(frame, 0.5);
  expect_valid_person_boxes(dets, frame, 0.5, 0.0f);
  EXPECT_GE(dets.size(), 1u);
  // A flat grey image has no people.
  EXPECT_TRUE(det->detect(cv::Mat(frame.size(), CV_8UC3, cv::Scalar::all(90)), 0.0).empty());
}

// Not an assertion of looks: writes the Fig. 3 picture for a real frame (fake flat depth) for a human to view.
TEST(FilterStagesImage, WritesPanelsForARealFrame) {
  if (!testdata::have_yolo() || !testdata::have_video()) GTEST_SKIP() << "needs the shared model and vtest.avi";
  const cv::Mat frame = testdata::vtest_frame(40);
  auto det = make_detector(yolo_config());
  const Detections dets = det->detect(frame, 0.0);
  cv::Mat gray;
  cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
  std::vector<cv::KeyPoint> kps;
  cv::ORB::create(1000)->detect(gray, kps);
  // Flat floor at 6 m; people at 3 m (their boxes' inner part), so the depth test has something to separate.
  cv::Mat depth(frame.size(), CV_32FC1, cv::Scalar(6.0f));
  for (const auto& d : dets) {
    const cv::Rect2f b = d.box;
    depth(cv::Rect(cv::Rect2f(b.x + 0.25f * b.width, b.y, 0.5f * b.width, b.height)) &
          cv::Rect(0, 0, depth.cols, depth.rows))
        .setTo(3.0f);
  }
  FilterStats stats;
  const auto keep = filter_keypoints(kps, depth, dets, FilterConfig{}, &stats);
  const cv::Mat img = draw_filter_stages(frame, kps, dets, keep);
  ASSERT_EQ(img.rows, frame.rows);
  ASSERT_EQ(img.cols, 3 * frame.cols);
  EXPECT_GT(stats.dropped, 0);
  EXPECT_GT(stats.kept_background, 0);
  const fs::path out = fs::path(::testing::TempDir()) / "varslam_semantic_filter_stages.png";
  ASSERT_TRUE(cv::imwrite(out.string(), img));
  std::cout << "filter stages image: " << out << " (" << dets.size() << " boxes, " << stats.in_boxes
            << " kps in boxes, " << stats.dropped << " dropped)\n";
}

}  // namespace
}  // namespace varslam::semantic
