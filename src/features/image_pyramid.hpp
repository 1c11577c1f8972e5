#pragma once
// Scale pyramid for feature extraction, reusing its buffers from one frame to the next.
#include <opencv2/core.hpp>
#include <vector>

namespace varslam {

/// levels[0] shares `gray`; level l has size round(size0 / scales[l]) and is resized bilinearly from
/// level l-1. A level that would be smaller than 1x1 is left empty.
void build_pyramid(const cv::Mat& gray, const std::vector<double>& scales, std::vector<cv::Mat>& levels);

/// Maps a pixel coordinate of a pyramid level to level 0 along one axis. Exact for bilinear resizing
/// (pixel centres at +0.5): multiplying by the nominal scale alone is off by (scale - 1) / 2 px.
inline float level_to_base(float coord, int base_size, int level_size) {
  return (coord + 0.5f) * static_cast<float>(base_size) / static_cast<float>(level_size) - 0.5f;
}

}  // namespace varslam
