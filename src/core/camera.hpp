#pragma once
// Pinhole camera of an RGB-D sensor, with the "virtual stereo" baseline ORB-SLAM uses for depth.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace varslam {

struct PinholeCamera {
  double fx = 525.0, fy = 525.0, cx = 319.5, cy = 239.5;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;  // OpenCV radial-tangential distortion
  int width = 640, height = 480;
  double bf = 40.0;  // fx * baseline [pixel * m]: u_right = u - bf / depth

  bool has_distortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }
  cv::Mat K() const;
  cv::Mat dist_coeffs() const;

  Eigen::Vector2d project(const Eigen::Vector3d& p_c) const {
    const double iz = 1.0 / p_c.z();
    return {fx * p_c.x() * iz + cx, fy * p_c.y() * iz + cy};
  }
  Eigen::Vector3d unproject(double u, double v, double depth) const {
    return {(u - cx) * depth / fx, (v - cy) * depth / fy, depth};
  }
  bool in_image(double u, double v, double border = 0.0) const {
    return u >= border && v >= border && u < width - border && v < height - border;
  }
};

/// The pinhole pixels of distorted pixels `px` (the inverse of the distortion model, iterated until it is exact to
/// 1e-3 px: OpenCV's default five iterations leave pixels off by up to 2 px at the corners of a Kinect v1's image).
std::vector<cv::Point2f> undistort_pixels(const PinholeCamera& camera, const std::vector<cv::Point2f>& px);

}  // namespace varslam
