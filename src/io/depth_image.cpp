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

// One row of the warp, arithmetic only: each pixel's target index in the colour image (-1: nothing lands) and its
// depth there. Selects instead of branches, because holes and borders come in patterns the branch predictor misses;
// the z-buffer stores are a second pass. The expressions are those of unproject() and project(), in the same
// order, so the pixels are exactly theirs.
void project_row(const float* depth, int cols, double v, const PinholeCamera& d, const Eigen::Vector3d& t,
                 const PinholeCamera& colour, int* target, float* z_out) {
  const double dcx = d.cx, dfx = d.fx, dfy = d.fy, tx = t.x(), ty = t.y(), tz = t.z();
  const double fx = colour.fx, fy = colour.fy, cx = colour.cx, cy = colour.cy;
  const double y_ray = v - d.cy, last_u = colour.width - 0.5, last_v = colour.height - 0.5;
  const int width = colour.width;
  for (int u = 0; u < cols; ++u) {
    const double z = depth[u];
    const double x = (u - dcx) * z / dfx + tx;
    const double y = y_ray * z / dfy + ty;
    const double zc = z + tz;
    const bool in_front = (z > 0.0) & (zc > 0.0);  // & not &&: no branch
    const double iz = 1.0 / (in_front ? zc : 1.0);
    const double pu = fx * x * iz + cx;
    const double pv = fy * y * iz + cy;
    const bool inside = in_front & (pu > -0.5) & (pu < last_u) & (pv > -0.5) & (pv < last_v);
    // Truncation and the exact fraction left round half away from zero, as std::lround does.
    const double su = inside ? pu : 0.0, sv = inside ? pv : 0.0;
    const int tu = static_cast<int>(su), tv = static_cast<int>(sv);
    const int cu = tu + static_cast<int>(su - tu >= 0.5), cv_ = tv + static_cast<int>(sv - tv >= 0.5);
    target[u] = inside ? cv_ * width + cu : -1;
    z_out[u] = static_cast<float>(zc);
  }
}

}  // namespace

cv::Mat register_depth_to_colour(const cv::Mat& depth_m, const DepthCameraRig& rig, const PinholeCamera& colour) {
  CV_Assert(depth_m.type() == CV_32FC1);
  cv::Mat out(colour.height, colour.width, CV_32FC1, cv::Scalar(0.0f));
  CV_Assert(out.isContinuous());
  auto* dst = out.ptr<float>();
  std::vector<int> target(static_cast<std::size_t>(depth_m.cols));
  std::vector<float> z(static_cast<std::size_t>(depth_m.cols));
  for (int v = 0; v < depth_m.rows; ++v) {
    project_row(depth_m.ptr<float>(v), depth_m.cols, v, rig.depth, rig.t_colour_depth, colour, target.data(), z.data());
    for (int u = 0; u < depth_m.cols; ++u) {
      const int i = target[std::size_t(u)];
      if (i < 0) continue;
      const float zc = z[std::size_t(u)];
      if (dst[i] == 0.0f || zc < dst[i]) dst[i] = zc;  // z-buffer: the nearer surface occludes the farther one
    }
  }
  return out;
}

}  // namespace varslam
