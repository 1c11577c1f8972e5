#include "semantic/filter_stages_image.hpp"

#include <opencv2/imgproc.hpp>

namespace varslam::semantic {
namespace {

const cv::Scalar kGreen(0, 220, 0), kRed(0, 0, 255), kYellow(0, 220, 255), kBlue(255, 160, 0);

cv::Mat as_bgr(const cv::Mat& img) {
  cv::Mat out;
  if (img.channels() == 1)
    cv::cvtColor(img, out, cv::COLOR_GRAY2BGR);
  else
    out = img.clone();
  return out;
}

void caption(cv::Mat& panel, const std::string& text) {
  cv::rectangle(panel, cv::Rect(0, 0, panel.cols, 26), cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(panel, text, cv::Point(6, 19), cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
}

bool in_any_box(const cv::Point2f& p, const Detections& boxes) {
  for (const auto& b : boxes)
    if (b.box.contains(p)) return true;
  return false;
}

}  // namespace

cv::Mat draw_filter_stages(const cv::Mat& bgr, const std::vector<cv::KeyPoint>& kps, const Detections& boxes,
                           const std::vector<bool>& keep) {
  if (bgr.empty()) return {};
  cv::Mat all = as_bgr(bgr), boxed = as_bgr(bgr), kept = as_bgr(bgr);
  int n_in_box = 0, n_kept = 0;
  for (const auto& b : boxes) {
    cv::rectangle(boxed, cv::Rect(b.box), kBlue, 2);
    cv::rectangle(kept, cv::Rect(b.box), kBlue, 1);
  }
  for (std::size_t i = 0; i < kps.size(); ++i) {
    const cv::Point2f& p = kps[i].pt;
    cv::circle(all, p, 3, kGreen, 1, cv::LINE_AA);
    // "In boxes" uses the filter's own verdict where it has one, so the enlarged boxes count too.
    const bool dropped = i < keep.size() && !keep[i];
    if (dropped || in_any_box(p, boxes)) {
      cv::circle(boxed, p, 3, kYellow, 1, cv::LINE_AA);
      ++n_in_box;
    }
    if (dropped) {
      cv::drawMarker(kept, p, kRed, cv::MARKER_TILTED_CROSS, 6, 1);
    } else {
      cv::circle(kept, p, 3, kGreen, 1, cv::LINE_AA);
      ++n_kept;
    }
  }
  caption(all, "extracted keypoints: " + std::to_string(kps.size()));
  caption(boxed, "in person boxes: " + std::to_string(n_in_box));
  caption(kept, "kept after depth test: " + std::to_string(n_kept) + " (x = dropped)");
  cv::Mat out;
  cv::hconcat(std::vector<cv::Mat>{all, boxed, kept}, out);
  return out;
}

}  // namespace varslam::semantic
