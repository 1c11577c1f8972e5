#include "features/orb_descriptor.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace varslam {

CentroidOrientation::CentroidOrientation(int radius) : radius_(radius), half_width_(std::size_t(radius) + 1) {
  // Integer test (no sqrt rounding) so the disc is exactly symmetric: x <-> y swaps map it onto itself.
  const int r2 = radius * radius + radius;
  for (int dy = 0; dy <= radius; ++dy) {
    int hw = 0;
    while ((hw + 1) * (hw + 1) + dy * dy <= r2) ++hw;
    half_width_[std::size_t(dy)] = hw;
  }
}

float CentroidOrientation::angle_deg(const cv::Mat& image, int x, int y) const {
  const std::uint8_t* centre = image.ptr<std::uint8_t>(y) + x;
  const std::ptrdiff_t step = static_cast<std::ptrdiff_t>(image.step1());
  int m10 = 0, m01 = 0;
  for (int dx = -half_width_[0]; dx <= half_width_[0]; ++dx) m10 += dx * centre[dx];
  // Rows +dy and -dy together: their x moments add, their y moments subtract.
  for (int dy = 1; dy <= radius_; ++dy) {
    const std::uint8_t* below = centre + dy * step;
    const std::uint8_t* above = centre - dy * step;
    const int hw = half_width_[std::size_t(dy)];
    int row_diff = 0;
    for (int dx = -hw; dx <= hw; ++dx) {
      m10 += dx * (below[dx] + above[dx]);
      row_diff += below[dx] - above[dx];
    }
    m01 += dy * row_diff;
  }
  float deg = static_cast<float>(std::atan2(double(m01), double(m10)) * (180.0 / std::numbers::pi));
  if (deg < 0.f) deg += 360.f;
  if (deg >= 360.f) deg -= 360.f;
  return deg;
}

namespace {

std::array<BriefPair, 256> make_brief_pattern() {
  std::mt19937 twister(0x0B1E5EEDu);  // mt19937's output sequence is fixed by the C++ standard
  const double sigma = 31.0 / 5.0;
  const auto uniform = [&] { return (double(twister()) + 0.5) / 4294967296.0; };  // in (0, 1)
  const auto sample_point = [&](std::int8_t& px, std::int8_t& py) {
    for (;;) {
      const double radius = sigma * std::sqrt(-2.0 * std::log(uniform()));
      const double phi = 2.0 * std::numbers::pi * uniform();
      const long x = std::lround(radius * std::cos(phi));
      const long y = std::lround(radius * std::sin(phi));
      if (x * x + y * y <= long(kOrbPatchRadius) * kOrbPatchRadius) {  // stays inside the patch when rotated
        px = static_cast<std::int8_t>(x);
        py = static_cast<std::int8_t>(y);
        return;
      }
    }
  };
  std::array<BriefPair, 256> pattern{};
  std::size_t n = 0;
  while (n < pattern.size()) {
    BriefPair p{};
    sample_point(p.x1, p.y1);
    sample_point(p.x2, p.y2);
    if (p.x1 == p.x2 && p.y1 == p.y2) continue;
    const auto same = [&](const BriefPair& q) {
      return (q.x1 == p.x1 && q.y1 == p.y1 && q.x2 == p.x2 && q.y2 == p.y2) ||
             (q.x1 == p.x2 && q.y1 == p.y2 && q.x2 == p.x1 && q.y2 == p.y1);
    };
    if (std::any_of(pattern.begin(), pattern.begin() + static_cast<std::ptrdiff_t>(n), same)) continue;
    pattern[n++] = p;
  }
  return pattern;
}

}  // namespace

const std::array<BriefPair, 256>& brief_pattern() {
  static const std::array<BriefPair, 256> pattern = make_brief_pattern();
  return pattern;
}

namespace {

// The pattern as float columns, so rotating all 512 points is one vectorisable loop.
struct PatternColumns {
  alignas(32) float x1[256], y1[256], x2[256], y2[256];
};

const PatternColumns& pattern_columns() {
  static const PatternColumns columns = [] {
    PatternColumns c{};
    const auto& pattern = brief_pattern();
    for (std::size_t i = 0; i < pattern.size(); ++i) {
      c.x1[i] = pattern[i].x1;
      c.y1[i] = pattern[i].y1;
      c.x2[i] = pattern[i].x2;
      c.y2[i] = pattern[i].y2;
    }
    return c;
  }();
  return columns;
}

}  // namespace

void rotated_brief(const cv::Mat& smoothed, int x, int y, float angle_deg, std::uint8_t* out) {
  const PatternColumns& p = pattern_columns();
  const double rad = double(angle_deg) * (std::numbers::pi / 180.0);
  const float c = static_cast<float>(std::cos(rad)), s = static_cast<float>(std::sin(rad));
  const std::uint8_t* centre = smoothed.ptr<std::uint8_t>(y) + x;
  const int step = static_cast<int>(smoothed.step1());
  // Rounds to the nearest pixel (halves up): |v| <= 15, so v + 16.5 > 0 and truncation is floor.
  const auto round_int = [](float v) { return static_cast<int>(v + 16.5f) - 16; };
  alignas(32) int off1[256], off2[256];
  for (int i = 0; i < 256; ++i) {
    off1[i] = round_int(s * p.x1[i] + c * p.y1[i]) * step + round_int(c * p.x1[i] - s * p.y1[i]);
    off2[i] = round_int(s * p.x2[i] + c * p.y2[i]) * step + round_int(c * p.x2[i] - s * p.y2[i]);
  }
  for (int byte = 0; byte < 32; ++byte) {
    unsigned v = 0;
    for (int bit = 0; bit < 8; ++bit) {
      const int i = byte * 8 + bit;
      v |= static_cast<unsigned>(centre[off1[i]] < centre[off2[i]]) << bit;
    }
    out[byte] = static_cast<std::uint8_t>(v);
  }
}

}  // namespace varslam
