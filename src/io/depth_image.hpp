#pragma once
// Raw 16-bit depth images to metres.
#include <opencv2/core.hpp>

namespace varslam {

/// CV_16UC1 raw depth -> CV_32FC1 metres (raw / depth_factor). Raw 0 and 65535 mean "no depth" and become 0.
cv::Mat depth_to_metres(const cv::Mat& raw, double depth_factor);

/// Median of the valid (> 0) depths in metres, sampling every `step`-th pixel in each direction; 0 if none.
double median_valid_depth(const cv::Mat& metres, int step = 4);

}  // namespace varslam
