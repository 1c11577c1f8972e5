#include "synth/preview.hpp"

#include <fmt/format.h>

#include <opencv2/imgproc.hpp>

namespace varslam::synth {

cv::Mat contact_sheet(const std::vector<PreviewFrame>& frames) {
  if (frames.empty()) return {};
  const int cols = 4;
  const int w = frames[0].bgr.cols / 2, h = frames[0].bgr.rows / 2;
  const int rows = (static_cast<int>(frames.size()) + cols - 1) / cols;
  cv::Mat sheet(rows * 2 * h, cols * w, CV_8UC3, cv::Scalar(0, 0, 0));
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const PreviewFrame& f = frames[i];
    const int c = static_cast<int>(i) % cols, r = static_cast<int>(i) / cols;
    cv::Mat rgb = f.bgr.clone();
    for (const auto& d : f.boxes) {
      cv::rectangle(rgb, cv::Rect(d.box), cv::Scalar(0, 255, 0), 2);
      cv::putText(rgb, d.label, cv::Point(static_cast<int>(d.box.x) + 3, static_cast<int>(d.box.y) + 16),
                  cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
    }
    cv::Mat small;
    cv::resize(rgb, small, cv::Size(w, h), 0, 0, cv::INTER_AREA);
    small.copyTo(sheet(cv::Rect(c * w, 2 * r * h, w, h)));
    // Depth 0..6 m to a colour map; missing depth stays black.
    cv::Mat1b d8;
    f.depth.convertTo(d8, CV_8U, 255.0 / (6.0 * f.depth_factor));
    cv::Mat col;
    cv::applyColorMap(d8, col, cv::COLORMAP_JET);
    col.setTo(cv::Scalar(0, 0, 0), f.depth == 0);
    cv::resize(col, small, cv::Size(w, h), 0, 0, cv::INTER_NEAREST);
    small.copyTo(sheet(cv::Rect(c * w, (2 * r + 1) * h, w, h)));
  }
  return sheet;
}

}  // namespace varslam::synth
