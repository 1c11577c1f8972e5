#include "slam/mover_track.hpp"

#include <algorithm>

namespace varslam::slam {

void MoverTrack::confirm(long frame_id, const Eigen::AlignedBox2f& region, float near_depth, float far_depth) {
  seen_ = true;
  confirmed_frame_ = frame_id;
  region_ = region;
  near_ = near_depth;
  far_ = far_depth;
}

std::pair<float, float> mover_depth_band(std::vector<float> depths, float ratio) {
  if (depths.empty()) return {0.0f, 0.0f};
  const auto mid = depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2);
  std::nth_element(depths.begin(), mid, depths.end());
  const float median = *mid;
  const auto [lo, hi] = std::minmax_element(depths.begin(), depths.end());
  return {std::max(*lo, median / ratio), std::min(*hi, median * ratio)};
}

bool MoverTrack::in_band(float depth) const {
  return seen_ && depth > 0 && depth >= (1 - cfg_.depth_margin) * near_ && depth <= (1 + cfg_.depth_margin) * far_;
}

bool MoverTrack::covers(const Eigen::Vector2f& px, float depth, float margin_px) const {
  if (!in_band(depth)) return false;
  const Eigen::Vector2f m(margin_px, margin_px);
  return (px.array() >= (region_.min() - m).array()).all() && (px.array() <= (region_.max() + m).array()).all();
}

}  // namespace varslam::slam
