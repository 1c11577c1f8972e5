#include "io/depth_image.hpp"

#include <algorithm>
#include <cmath>
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

namespace {

// The pixel std::lround(x) names when it lies in [0, size), else -1. Without the library call: a truncating
// conversion and the fraction left, which is exact in binary floating point (so half-way cases go away from zero,
// as std::lround does). The library call took a third of the warp's time.
int pixel_index(double x, int size) {
  if (!(x > -0.5 && x < size - 0.5)) return -1;  // NaN fails too
  int i = static_cast<int>(x);                     // toward zero
  const double fraction = x - i;
  if (fraction >= 0.5) ++i;
  return i;
}

}  // namespace

cv::Mat register_depth_to_colour(const cv::Mat& depth_m, const DepthCameraRig& rig, const PinholeCamera& colour) {
  CV_Assert(depth_m.type() == CV_32FC1);
  cv::Mat out(colour.height, colour.width, CV_32FC1, cv::Scalar(0.0f));
  const PinholeCamera& d = rig.depth;
  const Eigen::Vector3d& t = rig.t_colour_depth;
  for (int v = 0; v < depth_m.rows; ++v) {
    const auto* row = depth_m.ptr<float>(v);
    for (int u = 0; u < depth_m.cols; ++u) {
      const float z = row[u];
      if (!(z > 0.0f)) continue;
      const Eigen::Vector3d p = d.unproject(u, v, z) + t;
      if (p.z() <= 0.0) continue;
      const Eigen::Vector2d uv = colour.project(p);
      const int cu = pixel_index(uv.x(), out.cols);
      const int cv_ = pixel_index(uv.y(), out.rows);
      if (cu < 0 || cv_ < 0) continue;
      float& dst = out.at<float>(cv_, cu);
      const auto zc = static_cast<float>(p.z());
      if (dst == 0.0f || zc < dst) dst = zc;  // z-buffer: the nearer surface occludes the farther one
    }
  }
  return out;
}

}  // namespace varslam
