#pragma once
// Moves boxes detected on an older image onto the current one, so asynchronous detections a frame or two old
// still cover the person.
#include <opencv2/core.hpp>

#include "core/detection.hpp"

namespace varslam::semantic {

/// Shifts each box by the median sparse LK optical flow (cv::calcOpticalFlowPyrLK) of corners inside it, from
/// old_gray to cur_gray (CV_8UC1, same size). A box whose flow fails (too few corners or tracks) stays unchanged.
/// Timestamps and labels are kept (the caller knows how stale the detection is).
Detections propagate_boxes(const Detections& boxes, const cv::Mat& old_gray, const cv::Mat& cur_gray);

}  // namespace varslam::semantic
