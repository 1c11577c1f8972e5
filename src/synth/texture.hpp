#pragma once
// Procedural textures with natural (multi-scale) statistics and a mip pyramid, sampled with trilinear filtering
// so that distant surfaces average instead of aliasing into flicker.
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace varslam::synth {

class Texture {
 public:
  Texture() = default;
  /// bgr: CV_8UC3 with power-of-two width and height (it tiles: sampling wraps around).
  explicit Texture(const cv::Mat& bgr);
  /// Colour in [0,1] at texel coordinates (u, v) of level 0; footprint = size of one pixel in level-0 texels.
  cv::Vec3f sample(double u, double v, double footprint) const;
  int width() const { return levels_.empty() ? 0 : levels_[0].cols; }
  int height() const { return levels_.empty() ? 0 : levels_[0].rows; }
  const cv::Mat& level0() const { return levels_[0]; }

 private:
  cv::Vec3f bilinear(int level, double u, double v) const;
  std::vector<cv::Mat> levels_;
};

/// Generators. All return CV_8UC3 BGR images of the given power-of-two size, deterministic per seed.
namespace texgen {
/// Tileable fractal value noise in [0,1]: `cells` lattice cells across the image at the coarsest octave.
cv::Mat1f fbm(int w, int h, std::uint64_t seed, int cells, int octaves, double persistence = 0.5);
cv::Mat plaster(int size, cv::Vec3b base, std::uint64_t seed);
cv::Mat plain(int size, cv::Vec3b base, std::uint64_t seed);  // low texture: whiteboard, ceiling
cv::Mat wood(int size, cv::Vec3b base, std::uint64_t seed);
cv::Mat tiles(int size, int n_tiles, cv::Vec3b a, cv::Vec3b b, std::uint64_t seed);
cv::Mat carpet(int size, cv::Vec3b base, std::uint64_t seed);
cv::Mat poster(int w, int h, std::uint64_t seed);
cv::Mat bookshelf(int w, int h, int shelves, std::uint64_t seed);
cv::Mat fabric(int size, cv::Vec3b base, int pattern, std::uint64_t seed);  // 0 plain knit, 1 stripes, 2 checks
cv::Mat cardboard(int size, std::uint64_t seed);
cv::Mat screen(int w, int h, std::uint64_t seed);
}  // namespace texgen

}  // namespace varslam::synth
