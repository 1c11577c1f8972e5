#include "dense/mover_mask.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace varslam::dense {

cv::Mat mover_mask(const cv::Mat& depth, const MoverMaskInputs& in) {
  CV_Assert(depth.type() == CV_32FC1);
  cv::Mat mask(depth.size(), CV_8UC1, cv::Scalar(0));
  const cv::Rect image(0, 0, depth.cols, depth.rows);
  auto mark_band = [&](const cv::Rect& r, float lo, float hi, bool no_depth_too) {
    const cv::Rect roi = r & image;
    for (int v = roi.y; v < roi.y + roi.height; ++v) {
      const float* d = depth.ptr<float>(v);
      std::uint8_t* m = mask.ptr<std::uint8_t>(v);
      for (int u = roi.x; u < roi.x + roi.width; ++u)
        if ((d[u] > 0 && d[u] >= lo && d[u] <= hi) || (no_depth_too && !(d[u] > 0))) m[u] = 255;
    }
  };
  for (const PersonBand& p : in.people) {
    // Everything up to the far end of the person's band: a person's depth taken from the wrong histogram mode (a
    // small or half-hidden person, the room behind them) still leaves the person out; the room behind stays.
    if (p.depth_m > 0) mark_band(p.rect, 0.0f, p.depth_m + p.band_m, true);
    else mask(p.rect & image).setTo(255);
  }
  for (const NearMoverBand& n : in.near_movers) {
    const cv::Rect r(cv::Point(static_cast<int>(std::floor(n.region.x - n.margin_px)),
                               static_cast<int>(std::floor(n.region.y - n.margin_px))),
                     cv::Point(static_cast<int>(std::ceil(n.region.x + n.region.width + n.margin_px)) + 1,
                               static_cast<int>(std::ceil(n.region.y + n.region.height + n.margin_px)) + 1));
    mark_band(r, (1 - n.depth_margin) * n.near_m, (1 + n.depth_margin) * n.far_m, false);
  }
  const int rad = static_cast<int>(std::ceil(in.point_radius_px));
  const float r2 = in.point_radius_px * in.point_radius_px;
  for (const MovingPoint& p : in.moving_points) {
    const float tol = std::max(0.1f, 0.1f * p.depth_m);
    const int cu = static_cast<int>(std::lround(p.px.x)), cv_ = static_cast<int>(std::lround(p.px.y));
    for (int v = std::max(0, cv_ - rad); v <= std::min(depth.rows - 1, cv_ + rad); ++v)
      for (int u = std::max(0, cu - rad); u <= std::min(depth.cols - 1, cu + rad); ++u) {
        const float du = static_cast<float>(u - cu), dv = static_cast<float>(v - cv_);
        if (du * du + dv * dv > r2) continue;
        const float d = depth.at<float>(v, u);
        if (p.depth_m <= 0 || (d > 0 && std::abs(d - p.depth_m) <= tol)) mask.at<std::uint8_t>(v, u) = 255;
      }
  }
  if (!in.caller_mask.empty()) {
    CV_Assert(in.caller_mask.type() == CV_8UC1 && in.caller_mask.size() == depth.size());
    mask.setTo(255, in.caller_mask);
  }
  if (in.margin_px > 0 && cv::countNonZero(mask) > 0)
    cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * in.margin_px + 1, 2 * in.margin_px + 1)));
  return mask;
}

}  // namespace varslam::dense
