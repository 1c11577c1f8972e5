#pragma once
// RGB-D sensor effects applied to a clean rendering: Kinect-like depth noise and dropouts, 16-bit quantisation,
// motion blur, exposure gain and image noise.
#include <opencv2/core.hpp>

#include "synth/fast_rng.hpp"

namespace varslam::synth {

/// Standard deviation of Kinect-like depth noise at depth z (metres): 0.0012 + 0.0019 (z - 0.4)^2.
inline double kinect_depth_sigma(double z) { return 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4); }

struct DepthSensorParams {
  bool noise = true;
  bool edge_holes = true;
  double max_range_m = 5.5;  // 0 = unlimited
  int random_holes = 4;
  double depth_factor = 5000.0;
};

/// Clean depth (metres) -> 16-bit sensor depth (depth_factor units per metre, 0 = no depth).
cv::Mat1w sense_depth(const cv::Mat1f& depth_m, const DepthSensorParams& p, SplitMix64& rng, const GaussianTable& gauss);

/// Blur along the image motion (dx, dy) in pixels during the exposure (no-op below one pixel).
void motion_blur(cv::Mat3f& img, double dx, double dy);

/// Float image in [0, 1] -> 8-bit BGR with gain and Gaussian noise of sigma grey levels.
cv::Mat3b sense_color(const cv::Mat3f& img, double gain, double noise_sigma, SplitMix64& rng, const GaussianTable& gauss);

}  // namespace varslam::synth
