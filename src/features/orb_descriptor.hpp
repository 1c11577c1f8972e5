#pragma once
// The two per-keypoint parts of ORB: orientation by intensity centroid and the rotated BRIEF descriptor.
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace varslam {

inline constexpr int kOrbPatchRadius = 15;  // circular patch of diameter 31 at the keypoint's level

/// Orientation of the intensity centroid of a disc (x^2 + y^2 <= r^2 + r, symmetric under 90-degree turns)
/// around an integer pixel. Angle in degrees in [0, 360), measured in image axes (x right, y down).
class CentroidOrientation {
 public:
  explicit CentroidOrientation(int radius = kOrbPatchRadius);
  /// The caller keeps (x, y) at least `radius` pixels inside `image` (CV_8UC1).
  float angle_deg(const cv::Mat& image, int x, int y) const;
  int radius() const { return radius_; }

 private:
  int radius_;
  std::vector<int> half_width_;  // half_width_[|dy|]: disc row half-width
};

/// 256 point pairs inside the disc of radius kOrbPatchRadius, drawn from an isotropic Gaussian with
/// sigma = 31 / 5 (the BRIEF paper's G II sampling) by a fixed-seed Mersenne twister and our own Box-Muller
/// transform, so the pattern is the same on every platform. No pair repeats and no pair compares a point
/// with itself.
struct BriefPair {
  std::int8_t x1, y1, x2, y2;
};
const std::array<BriefPair, 256>& brief_pattern();

/// Rotated BRIEF: bit i of the descriptor is 1 when smoothed(p1_i) < smoothed(p2_i), with the pattern rotated
/// by `angle_deg` about (x, y). `smoothed` is the Gaussian-blurred level image (CV_8UC1); (x, y) must be at
/// least kOrbPatchRadius pixels inside it. Writes 32 bytes to `out`.
void rotated_brief(const cv::Mat& smoothed, int x, int y, float angle_deg, std::uint8_t* out);

}  // namespace varslam
