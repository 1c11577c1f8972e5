#pragma once
// Debug picture of the filter (the paper's Fig. 3): three panels side by side.
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <vector>

#include "core/detection.hpp"

namespace varslam::semantic {

/// extracted keypoints (with semantic.mask_extraction, none on the people) | keypoints inside boxes (boxes drawn) | keypoints kept after the depth test (dropped in red).
cv::Mat draw_filter_stages(const cv::Mat& bgr, const std::vector<cv::KeyPoint>& kps, const Detections& boxes,
                           const std::vector<bool>& keep);

}  // namespace varslam::semantic
