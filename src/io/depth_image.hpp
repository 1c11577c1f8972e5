#pragma once
// Raw 16-bit depth images to metres, and registration of a separate depth camera's image to the colour camera.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/camera.hpp"

namespace varslam {

/// CV_16UC1 raw depth -> CV_32FC1 metres (raw / depth_factor). Raw 0 and 65535 mean "no depth" and become 0.
cv::Mat depth_to_metres(const cv::Mat& raw, double depth_factor);

/// Median of the valid (> 0) depths in metres, sampling every `step`-th pixel in each direction; 0 if none.
double median_valid_depth(const cv::Mat& metres, int step = 4);

/// Where the depth camera sits relative to the colour camera (rotation taken as identity: both look the same
/// way on one rigid board, e.g. Kinect v1).
struct DepthCameraRig {
  PinholeCamera depth;                                // the depth camera's intrinsics (distortion ignored)
  Eigen::Vector3d t_colour_depth = Eigen::Vector3d::Zero();  // depth camera origin in the colour frame, metres
};

/// Forward-warps a depth image in metres (CV_32FC1, depth camera geometry) into the colour camera's pixel grid
/// (colour.width x colour.height): each valid depth pixel is unprojected with rig.depth, moved by
/// rig.t_colour_depth and projected with `colour`; where several land on one pixel the nearest wins (the far
/// one is occluded). Pixels nothing lands on stay 0 (no depth). Depth is z in the colour frame.
cv::Mat register_depth_to_colour(const cv::Mat& depth_m, const DepthCameraRig& rig, const PinholeCamera& colour);

}  // namespace varslam
