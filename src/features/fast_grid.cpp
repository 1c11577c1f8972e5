#include "features/fast_grid.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>

namespace varslam {
namespace {

constexpr int kFastRadius = 3;  // FAST tests a circle of radius 3 around each pixel

// Runs FAST on `rect` grown by the circle radius (so every pixel of `rect` is tested) and appends the
// corners that fall inside `rect`, in image coordinates.
void fast_in_rect(const cv::Mat& image, const cv::Rect& rect, int threshold, std::vector<cv::KeyPoint>& scratch,
                  std::vector<cv::KeyPoint>& out) {
  const cv::Rect grown =
      cv::Rect(rect.x - kFastRadius, rect.y - kFastRadius, rect.width + 2 * kFastRadius,
               rect.height + 2 * kFastRadius) &
      cv::Rect(0, 0, image.cols, image.rows);
  scratch.clear();
  cv::FAST(image(grown), scratch, threshold, true);
  for (cv::KeyPoint kp : scratch) {
    kp.pt.x += static_cast<float>(grown.x);
    kp.pt.y += static_cast<float>(grown.y);
    if (rect.contains(cv::Point(static_cast<int>(kp.pt.x), static_cast<int>(kp.pt.y)))) out.push_back(kp);
  }
}

}  // namespace

void detect_fast_grid(const cv::Mat& image, const cv::Rect& region, const FastGridParams& params,
                      std::vector<cv::KeyPoint>& corners) {
  if (region.width <= 0 || region.height <= 0 || image.empty()) return;
  const int cols = std::max(1, static_cast<int>(std::lround(region.width / double(std::max(1, params.cell_size)))));
  const int rows = std::max(1, static_cast<int>(std::lround(region.height / double(std::max(1, params.cell_size)))));
  // Cell boundaries: cell c spans [xs[c], xs[c+1]).
  std::vector<int> xs(static_cast<std::size_t>(cols + 1)), ys(static_cast<std::size_t>(rows + 1));
  for (int c = 0; c <= cols; ++c) xs[static_cast<std::size_t>(c)] = region.x + c * region.width / cols;
  for (int r = 0; r <= rows; ++r) ys[static_cast<std::size_t>(r)] = region.y + r * region.height / rows;
  const auto bin = [](const std::vector<int>& edges, int v) {
    return static_cast<int>(std::upper_bound(edges.begin() + 1, edges.end() - 1, v) - edges.begin()) - 1;
  };

  // One FAST pass over the whole region at the high threshold is the same search as one pass per cell,
  // without the per-call overhead; only the empty cells are searched again at the low threshold.
  const std::size_t first = corners.size();
  std::vector<cv::KeyPoint> scratch;
  scratch.reserve(4096);
  fast_in_rect(image, region, params.ini_threshold, scratch, corners);

  std::vector<unsigned char> occupied(static_cast<std::size_t>(cols * rows), 0);
  for (std::size_t i = first; i < corners.size(); ++i) {
    const int c = bin(xs, static_cast<int>(corners[i].pt.x));
    const int r = bin(ys, static_cast<int>(corners[i].pt.y));
    occupied[static_cast<std::size_t>(r * cols + c)] = 1;
  }
  if (params.min_threshold >= params.ini_threshold) return;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (occupied[static_cast<std::size_t>(r * cols + c)]) continue;
      const auto cu = static_cast<std::size_t>(c), ru = static_cast<std::size_t>(r);
      const cv::Rect cell(xs[cu], ys[ru], xs[cu + 1] - xs[cu], ys[ru + 1] - ys[ru]);
      fast_in_rect(image, cell, params.min_threshold, scratch, corners);
    }
  }
}

}  // namespace varslam
