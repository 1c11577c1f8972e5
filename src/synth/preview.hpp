#pragma once
// Contact sheet of a few generated frames: RGB with person boxes, and colour-mapped depth below each row.
#include <opencv2/core.hpp>
#include <vector>

#include "core/detection.hpp"

namespace varslam::synth {

struct PreviewFrame {
  cv::Mat3b bgr;
  cv::Mat1w depth;  // raw sensor depth
  Detections boxes;
  double depth_factor = 5000.0;
};

/// 4 frames per row pair, half resolution each.
cv::Mat contact_sheet(const std::vector<PreviewFrame>& frames);

}  // namespace varslam::synth
