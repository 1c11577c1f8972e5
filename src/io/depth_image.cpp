#include "io/depth_image.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace varslam {

cv::Mat depth_to_metres(const cv::Mat& raw, double depth_factor) {
  if (raw.type() != CV_16UC1) throw std::invalid_argument("depth_to_metres: expected a CV_16UC1 image");
  cv::Mat out(raw.size(), CV_32FC1);
  const float scale = static_cast<float>(1.0 / depth_factor);
  for (int y = 0; y < raw.rows; ++y) {
    const auto* src = raw.ptr<std::uint16_t>(y);
    auto* dst = out.ptr<float>(y);
    for (int x = 0; x < raw.cols; ++x) {
      const std::uint16_t v = src[x];
      // 65535 is the sensor's "no return" marker (7-Scenes), not a point 65 m away.
      dst[x] = (v == 0 || v == 65535) ? 0.0f : static_cast<float>(v) * scale;
    }
  }
  return out;
}

double median_valid_depth(const cv::Mat& metres, int step) {
  CV_Assert(metres.type() == CV_32FC1 && step >= 1);
  std::vector<float> valid;
  valid.reserve(static_cast<std::size_t>((metres.rows / step + 1) * (metres.cols / step + 1)));
  for (int y = 0; y < metres.rows; y += step) {
    const auto* row = metres.ptr<float>(y);
    for (int x = 0; x < metres.cols; x += step)
      if (row[x] > 0) valid.push_back(row[x]);
  }
  if (valid.empty()) return 0.0;
  auto mid = valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 2);
  std::nth_element(valid.begin(), mid, valid.end());
  return *mid;
}

}  // namespace varslam
