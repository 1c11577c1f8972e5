#pragma once
// FAST corners detected cell by cell, so weakly textured regions still get corners.
#include <opencv2/core.hpp>
#include <vector>

namespace varslam {

struct FastGridParams {
  int cell_size = 30;  // target cell side in pixels (cells tile the region exactly, so they vary slightly)
  int ini_threshold = 20;
  int min_threshold = 7;
};

/// FAST-9 corners (with non-maximum suppression) whose centres lie inside `region` of `image` (CV_8UC1).
/// Every cell of a grid over `region` is searched with ini_threshold; cells where that finds nothing are
/// searched again with min_threshold. `region` must keep 3 px from the image border (FAST's circle).
/// Corners are appended to `corners` in image coordinates, response = FAST score.
void detect_fast_grid(const cv::Mat& image, const cv::Rect& region, const FastGridParams& params,
                      std::vector<cv::KeyPoint>& corners);

}  // namespace varslam
