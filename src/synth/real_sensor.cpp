#include "synth/real_sensor.hpp"

#include <fmt/format.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "core/error.hpp"

namespace varslam::synth {

RealSensorEffects kinect1_sensor() {
  RealSensorEffects e;
  e.inverse_depth_step = 0.00285;  // the kitchen's depth steps: 2.8-2.9 mm * z^2 from 1 to 4 m
  e.depth_noise_blur_px = 3.0;     // the kitchen's depth is flat between steps (block matching smooths it)
  e.dark_dropout = 0.5;
  e.depth_time_offset_s = 0.016;   // unsynchronised colour and depth, paired within 20 ms
  e.depth_offset_m = Eigen::Vector3d(0.002, 0, 0);
  e.rolling_shutter_s = 0.025;
  e.k1 = 0.2312;                   // a Kinect v1 colour camera's radial calibration (TUM freiburg2)
  e.k2 = -0.7849;
  e.k3 = 0.9172;
  e.focal_error = 0.005;           // the kitchen's colour focal estimated from different frames spreads +-0.7 %
  e.principal_point_error_px = 2.0;
  return e;
}

namespace {

double parse_number(const std::string& key, const std::string& value, double lo, double hi) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != value.size() || !std::isfinite(v))
    throw InputError(fmt::format("sensor effect {}: '{}' is not a number", key, value));
  if (v < lo || v > hi) throw InputError(fmt::format("sensor effect {}: {} is outside [{}, {}]", key, v, lo, hi));
  return v;
}

struct Key {
  const char* name;
  double lo, hi;
  double RealSensorEffects::*field;
};

const Key kNumbers[] = {
    {"inverse_depth_step", 0, 0.05, &RealSensorEffects::inverse_depth_step},
    {"depth_noise_blur_px", 0, 20, &RealSensorEffects::depth_noise_blur_px},
    {"depth_scale", 0.8, 1.2, &RealSensorEffects::depth_scale},
    {"dark_dropout", 0, 1, &RealSensorEffects::dark_dropout},
    {"depth_time_offset_s", 0, 0.1, &RealSensorEffects::depth_time_offset_s},
    {"rolling_shutter_s", 0, 0.1, &RealSensorEffects::rolling_shutter_s},
    {"k1", -2, 2, &RealSensorEffects::k1},
    {"k2", -2, 2, &RealSensorEffects::k2},
    {"k3", -2, 2, &RealSensorEffects::k3},
    {"focal_error", -0.2, 0.2, &RealSensorEffects::focal_error},
    {"principal_point_error_px", -50, 50, &RealSensorEffects::principal_point_error_px},
};

}  // namespace

std::vector<std::string> sensor_effect_keys() {
  std::vector<std::string> out;
  for (const Key& k : kNumbers) out.emplace_back(k.name);
  out.emplace_back("depth_offset_m");
  out.emplace_back("distortion_in_settings");
  return out;
}

void set_sensor_effect(RealSensorEffects& e, const std::string& key, const std::string& value) {
  for (const Key& k : kNumbers)
    if (key == k.name) {
      e.*k.field = parse_number(key, value, k.lo, k.hi);
      return;
    }
  if (key == "depth_offset_m") {
    std::stringstream in(value);
    std::string part;
    std::vector<double> xyz;
    while (std::getline(in, part, ',')) xyz.push_back(parse_number(key, part, -0.1, 0.1));
    if (xyz.size() != 3) throw InputError(fmt::format("sensor effect {}: '{}' is not x,y,z in metres", key, value));
    e.depth_offset_m = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    return;
  }
  if (key == "distortion_in_settings") {
    if (value != "true" && value != "false")
      throw InputError(fmt::format("sensor effect {}: '{}' is not true or false", key, value));
    e.distortion_in_settings = value == "true";
    return;
  }
  std::string known;
  for (const std::string& k : sensor_effect_keys()) known += (known.empty() ? "" : ", ") + k;
  throw InputError(fmt::format("unknown sensor effect '{}' (known: {})", key, known));
}

nlohmann::json describe(const RealSensorEffects& e) {
  nlohmann::json j;
  for (const Key& k : kNumbers) j[k.name] = e.*k.field;
  j["depth_offset_m"] = {e.depth_offset_m.x(), e.depth_offset_m.y(), e.depth_offset_m.z()};
  j["distortion_in_settings"] = e.distortion_in_settings;
  return j;
}

PinholeCamera stated_camera(const PinholeCamera& true_camera, const RealSensorEffects& e) {
  PinholeCamera c = true_camera;
  c.fx *= 1.0 + e.focal_error;
  c.fy *= 1.0 + e.focal_error;
  c.cx += e.principal_point_error_px;
  c.cy += e.principal_point_error_px;
  if (e.distortion_in_settings) {
    c.k1 = e.k1;
    c.k2 = e.k2;
    c.k3 = e.k3;
  }
  return c;
}

void apply_rolling_shutter(cv::Mat3f& color, const cv::Mat1f& depth, const PinholeCamera& cam,
                           const Eigen::Isometry3d& T_wc, const std::function<Eigen::Isometry3d(int)>& pose_at_row) {
  cv::Mat1f map_x(color.size()), map_y(color.size());
  const Eigen::Isometry3d T_cw = T_wc.inverse();
  for (int v = 0; v < color.rows; ++v) {
    // Row v's camera relative to the rendered one: a point seen at (u, v) from the row's pose is fetched from where
    // the rendering saw it. The rendered depth at (u, v) stands in for the row's (motion within a readout is small).
    const Eigen::Isometry3d T_rel = T_cw * pose_at_row(v);
    for (int u = 0; u < color.cols; ++u) {
      const float z = depth(v, u);
      const Eigen::Vector3d p = T_rel * cam.unproject(u, v, z > 0 ? z : 3.0);
      if (p.z() <= 0.05) {
        map_x(v, u) = static_cast<float>(u);
        map_y(v, u) = static_cast<float>(v);
        continue;
      }
      const Eigen::Vector2d q = cam.project(p);
      map_x(v, u) = static_cast<float>(q.x());
      map_y(v, u) = static_cast<float>(q.y());
    }
  }
  cv::Mat3f out;
  cv::remap(color, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  color = out;
}

LensDistortion::LensDistortion(const PinholeCamera& cam, double k1, double k2, double k3) {
  // For every pixel of the distorted image, the pinhole pixel it shows: undistort the pixel grid.
  std::vector<cv::Point2f> grid;
  grid.reserve(static_cast<std::size_t>(cam.width * cam.height));
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) grid.emplace_back(static_cast<float>(u), static_cast<float>(v));
  PinholeCamera distorted = cam;
  distorted.k1 = k1;
  distorted.k2 = k2;
  distorted.k3 = k3;
  const std::vector<cv::Point2f> pinhole = undistort_pixels(distorted, grid);
  map_x_.create(cam.height, cam.width, CV_32FC1);
  map_y_.create(cam.height, cam.width, CV_32FC1);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const cv::Point2f& p = pinhole[static_cast<std::size_t>(v * cam.width + u)];
      map_x_.at<float>(v, u) = p.x;
      map_y_.at<float>(v, u) = p.y;
    }
}

void LensDistortion::apply(cv::Mat3f& color) const {
  cv::Mat3f out;
  cv::remap(color, out, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  color = out;
}

void LensDistortion::apply(cv::Mat1f& depth) const {
  cv::Mat1f out;
  cv::remap(depth, out, map_x_, map_y_, cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  depth = out;
}

void LensDistortion::apply(cv::Mat1b& ids) const {
  cv::Mat1b out;
  cv::remap(ids, out, map_x_, map_y_, cv::INTER_NEAREST, cv::BORDER_REPLICATE);
  ids = out;
}

}  // namespace varslam::synth
