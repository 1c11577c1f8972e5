// The depth camera's image warped into the colour camera's grid (depth.registration), per frame: a real 7-Scenes
// depth frame (640x480, Kinect v1) with the rig the kitchen's registration estimates, or a synthetic ramp when the
// shared data is absent.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "io/depth_image.hpp"

namespace {

cv::Mat depth_frame() {
  const std::filesystem::path f =
      std::filesystem::path(VARSLAM_SHARED_DIR) / "realdata" / "7scenes_redkitchen" / "depth" / "frame-000300.depth.png";
  const cv::Mat raw = cv::imread(f.string(), cv::IMREAD_UNCHANGED);
  if (!raw.empty() && raw.type() == CV_16UC1) return varslam::depth_to_metres(raw, 1000.0);
  cv::Mat ramp(480, 640, CV_32FC1);
  for (int v = 0; v < ramp.rows; ++v)
    for (int u = 0; u < ramp.cols; ++u) ramp.at<float>(v, u) = 0.8f + 0.005f * static_cast<float>(u + v);
  return ramp;
}

void BM_RegisterDepthToColour(benchmark::State& state) {
  const cv::Mat depth = depth_frame();
  varslam::PinholeCamera d, colour;
  d.fx = d.fy = 585.0;
  d.cx = 320.0;
  d.cy = 240.0;
  colour.fx = colour.fy = 532.3;
  colour.cx = 313.0;
  colour.cy = 238.0;
  const varslam::DepthCameraRig rig{d, Eigen::Vector3d(0.025, 0.0, 0.0)};
  for (auto _ : state) benchmark::DoNotOptimize(varslam::register_depth_to_colour(depth, rig, colour));
}
BENCHMARK(BM_RegisterDepthToColour)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
