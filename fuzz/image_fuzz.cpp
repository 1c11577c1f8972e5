// Image and depth decoding with the dataset's checks (size against the camera,
// 16-bit single-channel depth, depth scale): the first input byte picks which
// of the frame's two files the rest replaces. A frame is loaded or refused with
// InputError; what loads has the camera's size and finite, non-negative depth.
#include <cmath>
#include <fstream>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/error.hpp"
#include "fuzz_input.hpp"
#include "io/dataset.hpp"

namespace {

constexpr int kWidth = 16, kHeight = 12;

struct OneFrameDataset {
  std::filesystem::path dir = varslam::fuzz::scratch_dir() / "dataset";
  std::unique_ptr<varslam::Dataset> dataset;

  OneFrameDataset() {
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "rgb.txt") << "0.0 rgb.png\n";
    std::ofstream(dir / "depth.txt") << "0.0 depth.png\n";
    restore_colour();
    restore_depth();
    varslam::Settings s = varslam::default_settings();
    s.camera.width = kWidth;
    s.camera.height = kHeight;
    dataset = varslam::open_dataset(dir, s);
  }
  void restore_colour() const {
    cv::imwrite((dir / "rgb.png").string(), cv::Mat(kHeight, kWidth, CV_8UC3, cv::Scalar(40, 90, 200)));
  }
  void restore_depth() const {
    cv::imwrite((dir / "depth.png").string(), cv::Mat(kHeight, kWidth, CV_16UC1, cv::Scalar(5000)));
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace varslam;
  static const OneFrameDataset ds;
  static int last_fuzzed = -1;  // which file the previous input replaced:
                                // restore it only when switching
  if (size == 0) return 0;
  const int colour = data[0] & 1;
  if (last_fuzzed != -1 && last_fuzzed != colour) {
    if (colour)
      ds.restore_depth();
    else
      ds.restore_colour();
  }
  last_fuzzed = colour;
  fuzz::write_input(colour ? "dataset/rgb.png" : "dataset/depth.png", data + 1, size - 1);
  RgbdFrame f;
  try {
    f = ds.dataset->load(0);
  } catch (const InputError&) {
    return 0;
  }
  VARSLAM_FUZZ_EXPECT(f.bgr.cols == kWidth && f.bgr.rows == kHeight && f.bgr.type() == CV_8UC3);
  VARSLAM_FUZZ_EXPECT(f.gray.size() == f.bgr.size() && f.depth.size() == f.bgr.size());
  VARSLAM_FUZZ_EXPECT(f.depth.type() == CV_32FC1);
  for (int y = 0; y < f.depth.rows; ++y)
    for (int x = 0; x < f.depth.cols; ++x) {
      const float d = f.depth.at<float>(y, x);
      VARSLAM_FUZZ_EXPECT(std::isfinite(d) && d >= 0);
    }
  return 0;
}
