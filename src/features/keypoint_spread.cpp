#include "features/keypoint_spread.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <utility>

namespace varslam {
namespace {

// Maps a float to an unsigned integer with the same order (negative values included).
std::uint32_t ordered_bits(float v) {
  const auto u = std::bit_cast<std::uint32_t>(v);
  return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

std::uint32_t clamp16(float v) { return static_cast<std::uint32_t>(std::clamp(v, 0.f, 65535.f)); }

}  // namespace

std::vector<cv::KeyPoint> spread_keypoints(const std::vector<cv::KeyPoint>& candidates, const cv::Rect& region,
                                           int budget) {
  if (budget <= 0 || candidates.empty() || region.width <= 0 || region.height <= 0) return {};
  const std::size_t n = candidates.size();
  const double side = std::max(2.0, std::sqrt(double(region.area()) / budget));
  const int cols = std::max(1, static_cast<int>(std::ceil(region.width / side)));
  const int rows = std::max(1, static_cast<int>(std::ceil(region.height / side)));

  // 1. Strength order: response descending, then position, then input index, packed in integer keys so
  //    the one sort is cheap and the order is total (the result cannot depend on the input order).
  std::vector<std::pair<std::uint64_t, std::uint32_t>> strength(n);
  for (std::size_t i = 0; i < n; ++i) {
    const cv::KeyPoint& kp = candidates[i];
    const std::uint64_t key = (std::uint64_t(~ordered_bits(kp.response)) << 32) | (clamp16(kp.pt.y) << 16) |
                              clamp16(kp.pt.x);
    strength[i] = {key, static_cast<std::uint32_t>(i)};
  }
  std::sort(strength.begin(), strength.end());

  // 2. Rank of each corner within its cell: walking in strength order, the k-th corner seen in a cell has rank k.
  std::vector<std::uint32_t> seen_in_cell(std::size_t(cols) * std::size_t(rows), 0);
  std::vector<std::uint32_t> rank(n);
  std::uint32_t max_rank = 0;
  for (std::size_t s = 0; s < n; ++s) {
    const cv::KeyPoint& kp = candidates[strength[s].second];
    const int c = std::clamp(static_cast<int>((kp.pt.x - float(region.x)) / side), 0, cols - 1);
    const int r = std::clamp(static_cast<int>((kp.pt.y - float(region.y)) / side), 0, rows - 1);
    rank[s] = seen_in_cell[std::size_t(r) * std::size_t(cols) + std::size_t(c)]++;
    max_rank = std::max(max_rank, rank[s]);
  }

  // 3. Round-robin order = by rank, strongest first within a rank: a stable counting sort on rank.
  std::vector<std::size_t> start(std::size_t(max_rank) + 2, 0);
  for (std::size_t s = 0; s < n; ++s) ++start[rank[s] + 1];
  for (std::size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
  const std::size_t keep = std::min(n, static_cast<std::size_t>(budget));
  std::vector<cv::KeyPoint> kept(keep);
  for (std::size_t s = 0; s < n; ++s) {
    const std::size_t slot = start[rank[s]]++;
    if (slot < keep) kept[slot] = candidates[strength[s].second];
  }
  return kept;
}

}  // namespace varslam
