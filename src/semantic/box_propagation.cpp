#include "semantic/box_propagation.hpp"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace varslam::semantic {
namespace {

constexpr int kMaxCornersPerBox = 40;
constexpr int kMinTracks = 3;
constexpr float kMaxFbError = 1.0f;  // px: forward-backward check rejects tracks that do not come back

float median(std::vector<float> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// The central part of a person box: mostly the person, less of the background around it.
cv::Rect inner_region(const cv::Rect2f& box, const cv::Size& size) {
  const cv::Rect2f inner(box.x + 0.2f * box.width, box.y + 0.1f * box.height, 0.6f * box.width,
                         0.8f * box.height);
  return cv::Rect(inner) & cv::Rect(0, 0, size.width, size.height);
}

}  // namespace

Detections propagate_boxes(const Detections& boxes, const cv::Mat& old_gray, const cv::Mat& cur_gray) {
  if (boxes.empty() || old_gray.empty() || cur_gray.empty() || old_gray.size() != cur_gray.size() ||
      old_gray.type() != CV_8UC1 || cur_gray.type() != CV_8UC1)
    return boxes;

  // Corners of every box in one list, so LK builds the pyramids once.
  std::vector<cv::Point2f> pts;
  std::vector<std::size_t> owner;
  std::vector<cv::Point2f> corners;
  for (std::size_t b = 0; b < boxes.size(); ++b) {
    const cv::Rect roi = inner_region(boxes[b].box, old_gray.size());
    if (roi.width < 8 || roi.height < 8) continue;
    cv::goodFeaturesToTrack(old_gray(roi), corners, kMaxCornersPerBox, 0.01, 4.0);
    for (const auto& c : corners) {
      pts.emplace_back(c.x + static_cast<float>(roi.x), c.y + static_cast<float>(roi.y));
      owner.push_back(b);
    }
  }
  if (pts.empty()) return boxes;

  std::vector<cv::Point2f> fwd, back;
  std::vector<uchar> st_f, st_b;
  std::vector<float> err;
  const cv::Size win(21, 21);
  cv::calcOpticalFlowPyrLK(old_gray, cur_gray, pts, fwd, st_f, err, win, 3);
  cv::calcOpticalFlowPyrLK(cur_gray, old_gray, fwd, back, st_b, err, win, 3);

  std::vector<std::vector<float>> dx(boxes.size()), dy(boxes.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!st_f[i] || !st_b[i]) continue;
    const cv::Point2f d = back[i] - pts[i];
    if (d.dot(d) > kMaxFbError * kMaxFbError) continue;
    dx[owner[i]].push_back(fwd[i].x - pts[i].x);
    dy[owner[i]].push_back(fwd[i].y - pts[i].y);
  }

  Detections out = boxes;
  for (std::size_t b = 0; b < out.size(); ++b) {
    if (static_cast<int>(dx[b].size()) < kMinTracks) continue;  // flow failed: keep the box as it was
    out[b].box.x += median(dx[b]);
    out[b].box.y += median(dy[b]);
  }
  return out;
}

}  // namespace varslam::semantic
