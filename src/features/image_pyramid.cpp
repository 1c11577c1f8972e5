#include "features/image_pyramid.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace varslam {

void build_pyramid(const cv::Mat& gray, const std::vector<double>& scales, std::vector<cv::Mat>& levels) {
  levels.resize(scales.size());
  if (levels.empty()) return;
  levels[0] = gray;
  for (std::size_t l = 1; l < scales.size(); ++l) {
    const int w = static_cast<int>(std::lround(gray.cols / scales[l]));
    const int h = static_cast<int>(std::lround(gray.rows / scales[l]));
    if (w < 1 || h < 1 || levels[l - 1].empty()) {
      levels[l].release();
      continue;
    }
    // Resizing from the previous level (not from level 0) keeps each step a small, well-sampled reduction.
    cv::resize(levels[l - 1], levels[l], cv::Size(w, h), 0, 0, cv::INTER_LINEAR);
  }
}

}  // namespace varslam
