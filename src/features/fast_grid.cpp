#include "features/fast_grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <opencv2/features2d.hpp>

namespace varslam {
namespace {

constexpr int kFastRadius = 3;  // FAST tests a circle of radius 3 around each pixel

// Scratch space of one detect_fast_grid call.
struct FastScratch {
  std::vector<cv::KeyPoint> corners;
  std::vector<std::uint8_t> scores;
};

// `rect` grown by FAST's circle radius on every side (within the image), so that FAST tests every pixel of `rect`.
cv::Rect grown_for_fast(const cv::Rect& rect, const cv::Mat& image) {
  return cv::Rect(rect.x - kFastRadius, rect.y - kFastRadius, rect.width + 2 * kFastRadius,
                  rect.height + 2 * kFastRadius) &
         cv::Rect(0, 0, image.cols, image.rows);
}

// Runs FAST on `rect` grown by the circle radius (so every pixel of `rect` is tested) and appends the
// corners that fall inside `rect`, in image coordinates.
void fast_in_rect(const cv::Mat& image, const cv::Rect& rect, int threshold, FastScratch& scratch,
                  std::vector<cv::KeyPoint>& out) {
  const cv::Rect grown = grown_for_fast(rect, image);
  scratch.corners.clear();
  cv::FAST(image(grown), scratch.corners, threshold, true);
  for (cv::KeyPoint kp : scratch.corners) {
    kp.pt.x += static_cast<float>(grown.x);
    kp.pt.y += static_cast<float>(grown.y);
    if (rect.contains(cv::Point(static_cast<int>(kp.pt.x), static_cast<int>(kp.pt.y)))) out.push_back(kp);
  }
}

// FAST's score of a corner, as cv::FAST defines it for non-maximum suppression: the largest threshold at which
// it still is one, i.e. over the nine-pixel arcs of the radius-3 circle the best arc's smallest difference to the
// centre (in the arc's direction), minus one.
int fast_score(const std::uint8_t* centre, std::ptrdiff_t step) {
  static constexpr int dx[16] = {0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3, -3, -3, -2, -1};
  static constexpr int dy[16] = {3, 3, 2, 1, 0, -1, -2, -3, -3, -3, -2, -1, 0, 1, 2, 3};
  std::array<int, 16 + 8> d{};  // centre minus circle pixel, in order around the circle, the first eight again
  for (std::size_t k = 0; k < 16; ++k) d[k] = centre[0] - centre[dx[k] + dy[k] * step];
  for (std::size_t k = 0; k < 8; ++k) d[16 + k] = d[k];
  int best = 0;
  for (std::size_t start = 0; start < 16; ++start) {
    int darker = 255, brighter = 255;
    for (std::size_t k = start; k < start + 9; ++k) {
      darker = std::min(darker, d[k]);
      brighter = std::min(brighter, -d[k]);
    }
    best = std::max({best, darker, brighter});
  }
  return best - 1;
}

// The corners fast_in_rect finds in each of the cells [c_begin, c_end) of one row of cells (columns at xs, rows
// y0..y1), appended cell by cell, with one FAST call for all of them: each call has a fixed cost of a few
// microseconds, and a textureless wall leaves hundreds of empty cells per frame. FAST finds the candidates
// without suppression; the suppression is then done per cell, with the neighbours outside the cell counting as
// no corner, which is what a call on that cell alone sees.
void fast_in_cells(const cv::Mat& image, const std::vector<int>& xs, int c_begin, int c_end, int y0, int y1,
                   int threshold, FastScratch& scratch, std::vector<cv::KeyPoint>& out) {
  const int x0 = xs[std::size_t(c_begin)], x1 = xs[std::size_t(c_end)];
  const int width = x1 - x0, height = y1 - y0;
  const cv::Rect grown = grown_for_fast(cv::Rect(x0, y0, width, height), image);
  scratch.corners.clear();
  cv::FAST(image(grown), scratch.corners, threshold, false);
  scratch.scores.assign(std::size_t(width) * std::size_t(height), 0);
  const auto step = static_cast<std::ptrdiff_t>(image.step1());
  for (cv::KeyPoint& kp : scratch.corners) {
    kp.pt.x += static_cast<float>(grown.x);
    kp.pt.y += static_cast<float>(grown.y);
    const int x = static_cast<int>(kp.pt.x), y = static_cast<int>(kp.pt.y);
    if (x < x0 || x >= x1 || y < y0 || y >= y1) continue;
    const int score = fast_score(image.ptr<std::uint8_t>(y) + x, step);
    kp.response = static_cast<float>(score);
    scratch.scores[std::size_t(y - y0) * std::size_t(width) + std::size_t(x - x0)] = static_cast<std::uint8_t>(score);
  }
  for (int c = c_begin; c < c_end; ++c) {
    const int cx0 = xs[std::size_t(c)], cx1 = xs[std::size_t(c + 1)];
    const auto score_at = [&](int x, int y) -> int {
      if (x < cx0 || x >= cx1 || y < y0 || y >= y1) return 0;
      return scratch.scores[std::size_t(y - y0) * std::size_t(width) + std::size_t(x - x0)];
    };
    for (const cv::KeyPoint& kp : scratch.corners) {
      const int x = static_cast<int>(kp.pt.x), y = static_cast<int>(kp.pt.y);
      if (x < cx0 || x >= cx1 || y < y0 || y >= y1) continue;
      const int s = score_at(x, y);
      if (s > score_at(x - 1, y - 1) && s > score_at(x, y - 1) && s > score_at(x + 1, y - 1) &&
          s > score_at(x - 1, y) && s > score_at(x + 1, y) && s > score_at(x - 1, y + 1) && s > score_at(x, y + 1) &&
          s > score_at(x + 1, y + 1))
        out.push_back(kp);
    }
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
  FastScratch scratch;
  scratch.corners.reserve(4096);
  fast_in_rect(image, region, params.ini_threshold, scratch, corners);

  std::vector<unsigned char> occupied(static_cast<std::size_t>(cols * rows), 0);
  for (std::size_t i = first; i < corners.size(); ++i) {
    const int c = bin(xs, static_cast<int>(corners[i].pt.x));
    const int r = bin(ys, static_cast<int>(corners[i].pt.y));
    occupied[static_cast<std::size_t>(r * cols + c)] = 1;
  }
  if (params.min_threshold >= params.ini_threshold) return;
  for (int r = 0; r < rows; ++r) {
    const auto ru = static_cast<std::size_t>(r);
    for (int c = 0; c < cols;) {
      if (occupied[static_cast<std::size_t>(r * cols + c)]) {
        ++c;
        continue;
      }
      int end = c + 1;  // empty cells side by side share one FAST call
      while (end < cols && !occupied[static_cast<std::size_t>(r * cols + end)]) ++end;
      fast_in_cells(image, xs, c, end, ys[ru], ys[ru + 1], params.min_threshold, scratch, corners);
      c = end;
    }
  }
}

}  // namespace varslam
