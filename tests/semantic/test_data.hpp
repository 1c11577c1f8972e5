#pragma once
// Shared helpers of the semantic tests: where the optional real data lives.
#include <filesystem>
#include <opencv2/videoio.hpp>
#include <string>

namespace varslam::semantic::testdata {

inline std::filesystem::path models_dir() { return std::filesystem::path(VARSLAM_SHARED_DIR) / "models"; }
inline std::filesystem::path vtest_video() { return "/usr/share/doc/opencv-doc/examples/data/vtest.avi"; }
inline bool have_yolo() {  // both presets: the default (body) and the 80-class XL
  for (const char* preset : {"yolo-fastest-1.1_body", "yolo-fastest-1.1-xl"})
    for (const char* ext : {".cfg", ".weights"})
      if (!std::filesystem::exists(models_dir() / (std::string(preset) + ext))) return false;
  return true;
}
inline bool have_video() { return std::filesystem::exists(vtest_video()); }

/// Frame `index` of vtest.avi (768x576 BGR, people walking); empty if unreadable.
inline cv::Mat vtest_frame(int index) {
  cv::VideoCapture cap(vtest_video().string());
  cv::Mat frame;
  for (int i = 0; i <= index && cap.read(frame); ++i) {
  }
  return frame;
}

}  // namespace varslam::semantic::testdata
