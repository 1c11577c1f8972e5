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
  // Real-sensor effects (synth/real_sensor.hpp), off at 0 / 1:
  double noise_blur_px = 0;       // noise smoothed over this many pixels (same standard deviation per pixel)
  double inverse_depth_step = 0;  // 1/m: reported depth in steps of 1/z
  double scale = 1.0;             // reported / true depth
  double dark_dropout = 0;        // chance of no depth where the colour is dark
};

/// Clean depth (metres) -> 16-bit sensor depth (depth_factor units per metre, 0 = no depth). `color` (the rendered
/// colour, for dark_dropout) may be null.
cv::Mat1w sense_depth(const cv::Mat1f& depth_m, const DepthSensorParams& p, SplitMix64& rng, const GaussianTable& gauss,
                      const cv::Mat3f* color = nullptr);

/// Blur along the image motion (dx, dy) in pixels during the exposure (no-op below one pixel).
void motion_blur(cv::Mat3f& img, double dx, double dy);

/// Float image in [0, 1] -> 8-bit BGR with gain and Gaussian noise of sigma grey levels.
cv::Mat3b sense_color(const cv::Mat3f& img, double gain, double noise_sigma, SplitMix64& rng, const GaussianTable& gauss);

}  // namespace varslam::synth
