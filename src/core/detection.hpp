#pragma once
// A detected object box in image pixels (known movers, e.g. COCO "person").
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace varslam {

struct Detection {
  double timestamp = 0.0;  // of the image the box was detected in
  std::string label;       // class name, e.g. "person"
  float score = 1.0f;
  cv::Rect2f box;  // x, y, w, h in pixels
};

using Detections = std::vector<Detection>;

}  // namespace varslam
