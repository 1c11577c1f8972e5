#pragma once
// What a real RGB-D camera adds beyond per-pixel noise, each effect a setting (all off by default, so existing
// sequences render byte for byte as before): depth in steps of disparity, spatially correlated depth noise, a depth
// scale error, depth lost on dark surfaces, a colour/depth time offset and misregistration, a rolling-shutter
// colour camera, lens distortion, and intrinsics that are slightly wrong in the written settings.
// kinect1_sensor() is the preset measured against the real 7-Scenes kitchen (docs/synth.md says how).
#include <Eigen/Geometry>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/camera.hpp"

namespace varslam::synth {

struct RealSensorEffects {
  double inverse_depth_step = 0;       // 1/m: depth comes in steps of 1/z (a disparity step); 0 = continuous
  double depth_noise_blur_px = 0;      // the depth noise is smooth over this many pixels (Gaussian sigma); 0 = per pixel
  double depth_scale = 1.0;            // reported depth / true depth
  double dark_dropout = 0;             // chance that a pixel on a dark surface (luminance < 0.1) has no depth
  double depth_time_offset_s = 0;      // the depth image is taken this long after the colour image (and stamped so)
  Eigen::Vector3d depth_offset_m = Eigen::Vector3d::Zero();  // depth camera in the colour camera's frame, left after
                                                              // registration (the depth is rendered from there)
  double rolling_shutter_s = 0;        // colour readout time from the first row to the last
  double k1 = 0, k2 = 0, k3 = 0;       // colour and depth lens distortion (radial)
  bool distortion_in_settings = true;  // settings.yaml states k1, k2, k3 (else the system is not told)
  double focal_error = 0;              // settings.yaml's fx, fy = true * (1 + focal_error)
  double principal_point_error_px = 0; // settings.yaml's cx, cy = true + this

  bool renders_depth_apart() const { return depth_time_offset_s != 0 || !depth_offset_m.isZero(); }
  bool distorts() const { return k1 != 0 || k2 != 0 || k3 != 0; }
};

/// Every effect set as measured on the real kitchen and from the Kinect v1's published specifications.
RealSensorEffects kinect1_sensor();

/// Sets one effect by its name in scenario.json ("inverse_depth_step", "depth_offset_m" as "x,y,z", ...).
/// InputError naming the key for an unknown key or a value out of range.
void set_sensor_effect(RealSensorEffects& e, const std::string& key, const std::string& value);
std::vector<std::string> sensor_effect_keys();
nlohmann::json describe(const RealSensorEffects& e);

/// The camera settings.yaml states: the rendering camera with the intrinsics error and (if told) the distortion.
PinholeCamera stated_camera(const PinholeCamera& true_camera, const RealSensorEffects& e);

/// Rolling shutter: row v of the colour image is seen from pose_at_row(v) instead of T_wc (the pose the image was
/// rendered from); each pixel is fetched from where its surface point (by the rendered depth) was seen at T_wc.
void apply_rolling_shutter(cv::Mat3f& color, const cv::Mat1f& depth, const PinholeCamera& cam,
                           const Eigen::Isometry3d& T_wc, const std::function<Eigen::Isometry3d(int)>& pose_at_row);

/// Radial distortion of a pinhole rendering: maps built once per camera.
class LensDistortion {
 public:
  LensDistortion(const PinholeCamera& cam, double k1, double k2, double k3);
  void apply(cv::Mat3f& color) const;
  void apply(cv::Mat1f& depth) const;  // nearest: depth is not blended across edges
  void apply(cv::Mat1b& ids) const;

 private:
  cv::Mat map_x_, map_y_;  // distorted pixel -> pinhole pixel
};

}  // namespace varslam::synth
