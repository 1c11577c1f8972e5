// Cost of the semantic stage: YOLO detectors (320/416 input, 1 or 2 OpenCV threads), HOG, the depth-aware
// keypoint filter and box propagation. Models come from VARSLAM_SHARED_DIR/models; absent -> the case is skipped.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "semantic/box_propagation.hpp"
#include "semantic/detector.hpp"
#include "semantic/keypoint_filter.hpp"

namespace {
namespace fs = std::filesystem;
using namespace varslam;
using namespace varslam::semantic;

const fs::path kModels = fs::path(VARSLAM_SHARED_DIR) / "models";
const char* const kVideo = "/usr/share/doc/opencv-doc/examples/data/vtest.avi";

cv::Mat video_frame(int index) {
  cv::VideoCapture cap(kVideo);
  cv::Mat f;
  for (int i = 0; i <= index && cap.read(f); ++i) {
  }
  if (f.empty()) f = cv::Mat(576, 768, CV_8UC3, cv::Scalar::all(120));  // still measures the cost
  return f;
}

// args: input size, OpenCV threads
void run_yolo(benchmark::State& state, const std::string& model) {
  if (!fs::exists(kModels / (model + ".weights"))) {
    state.SkipWithError(("model not found in " + kModels.string()).c_str());
    return;
  }
  DetectorConfig cfg;
  cfg.source = "yolo";
  cfg.model = model;
  cfg.model_dir = kModels;
  cfg.input_size = static_cast<int>(state.range(0));
  cfg.num_threads = static_cast<int>(state.range(1));
  auto det = make_detector(cfg);
  const cv::Mat frame = video_frame(40);
  det->detect(frame, 0.0);  // first run allocates
  std::size_t boxes = 0;
  for (auto _ : state) boxes = det->detect(frame, 0.0).size();
  state.counters["boxes"] = static_cast<double>(boxes);
  cv::setNumThreads(-1);
}
void BM_YoloFastestXl(benchmark::State& state) { run_yolo(state, "yolo-fastest-1.1-xl"); }
void BM_YoloFastestBody(benchmark::State& state) { run_yolo(state, "yolo-fastest-1.1_body"); }
BENCHMARK(BM_YoloFastestXl)->ArgsProduct({{224, 256, 320, 416}, {1, 2}})->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_YoloFastestBody)->ArgsProduct({{224, 256, 320}, {1, 2}})->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_Hog(benchmark::State& state) {
  DetectorConfig cfg;
  cfg.source = "hog";
  auto det = make_detector(cfg);
  cv::Mat frame = video_frame(40);
  if (state.range(0) != frame.cols) cv::resize(frame, frame, cv::Size(640, 480));
  std::size_t boxes = 0;
  for (auto _ : state) boxes = det->detect(frame, 0.0).size();
  state.counters["boxes"] = static_cast<double>(boxes);
}
BENCHMARK(BM_Hog)->Arg(640)->Arg(768)->Unit(benchmark::kMillisecond);

// 640x480 depth: wall at 4 m, `boxes` people at 1.5 m; 1000 keypoints spread over the image.
void BM_FilterKeypoints(benchmark::State& state) {
  const int n_boxes = static_cast<int>(state.range(0));
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(4.0f));
  Detections boxes;
  const int spacing = 600 / n_boxes;
  for (int b = 0; b < n_boxes; ++b) {
    Detection d;
    d.label = "person";
    d.box = cv::Rect2f(static_cast<float>(20 + spacing * b), 60, 100, 360);
    depth(cv::Rect(45 + spacing * b, 60, 50, 360)).setTo(1.5f);
    boxes.push_back(d);
  }
  cv::RNG rng(7);
  std::vector<cv::KeyPoint> kps;
  for (int i = 0; i < 1000; ++i) kps.emplace_back(rng.uniform(0.f, 640.f), rng.uniform(0.f, 480.f), 7.f);
  FilterStats stats;
  for (auto _ : state) benchmark::DoNotOptimize(filter_keypoints(kps, depth, boxes, FilterConfig{}, &stats));
  state.counters["in_boxes"] = stats.in_boxes;
  state.counters["dropped"] = stats.dropped;
}
BENCHMARK(BM_FilterKeypoints)->Arg(1)->Arg(3)->Arg(5)->Unit(benchmark::kMicrosecond);

void BM_PropagateBoxes(benchmark::State& state) {
  cv::Mat a, b;
  cv::cvtColor(video_frame(40), a, cv::COLOR_BGR2GRAY);
  cv::cvtColor(video_frame(42), b, cv::COLOR_BGR2GRAY);
  Detections boxes;
  for (int i = 0; i < 3; ++i) {
    Detection d;
    d.box = cv::Rect2f(100.f + 200.f * static_cast<float>(i), 150, 60, 150);
    boxes.push_back(d);
  }
  for (auto _ : state) benchmark::DoNotOptimize(propagate_boxes(boxes, a, b));
}
BENCHMARK(BM_PropagateBoxes)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
