#pragma once
// Synthetic scenes for the place-recognition, relocalization and loop-closing tests: world points with random
// ORB-like descriptors, seen by pinhole cameras at known poses as ready-made FrameFeatures (keypoints, depth,
// u_right, descriptors, scale info, grid), so the SLAM back end can be tested without images.
#include <Eigen/Geometry>
#include <cmath>
#include <memory>
#include <opencv2/core.hpp>
#include <random>
#include <set>
#include <vector>

#include "features/descriptor_matching.hpp"
#include "slam/frame.hpp"

namespace varslam::slam::synthetic {

inline std::shared_ptr<const ScaleInfo> scale_info() {
  auto s = std::make_shared<ScaleInfo>();
  double f = 1.0;
  for (int l = 0; l < s->n_levels; ++l, f *= s->scale_factor) {
    s->scale_factors.push_back(f);
    s->level_sigma2.push_back(f * f);
    s->inv_level_sigma2.push_back(1 / (f * f));
  }
  s->log_scale_factor = std::log(s->scale_factor);
  return s;
}

inline cv::Mat random_descriptors(int n, std::mt19937& rng) {
  cv::Mat d(n, kDescriptorBytes, CV_8U);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < kDescriptorBytes; ++c) d.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(byte(rng));
  return d;
}

/// Flips `bits` distinct random bits of a 1x32 descriptor row in place (observation noise).
inline void flip_bits(cv::Mat row, int bits, std::mt19937& rng) {
  std::uniform_int_distribution<int> bit(0, 8 * kDescriptorBytes - 1);
  std::set<int> chosen;
  while (static_cast<int>(chosen.size()) < bits) chosen.insert(bit(rng));
  for (int b : chosen) row.at<std::uint8_t>(0, b / 8) ^= static_cast<std::uint8_t>(1u << (b % 8));
}

/// A keypoint as a test states it: pixel, depth (<= 0: none), response, pyramid level.
struct Keypoint {
  double u = 0, v = 0, depth = -1;
  float response = 1.0f;
  int octave = 0;
};

/// FrameFeatures from stated keypoints and descriptors (one row each), as make_frame_features would build them
/// from an undistorted image: u_right from depth, grid built. All keypoint angles are 0 (rotation-consistent).
inline std::shared_ptr<FrameFeatures> make_features(const std::vector<Keypoint>& kps, const cv::Mat& descriptors,
                                                    const PinholeCamera& camera = {}) {
  auto f = std::make_shared<FrameFeatures>();
  f->camera = camera;
  f->scale = scale_info();
  f->descriptors = descriptors.clone();
  for (const Keypoint& k : kps) {
    f->keypoints.emplace_back(cv::Point2f(static_cast<float>(k.u), static_cast<float>(k.v)), 31.0f, 0.0f, k.response,
                              k.octave);
    f->depth.push_back(k.depth > 0 ? static_cast<float>(k.depth) : -1.0f);
    f->u_right.push_back(k.depth > 0 ? static_cast<float>(k.u - camera.bf / k.depth) : -1.0f);
  }
  f->build_grid();
  return f;
}

/// World points, each with its own descriptor (every sighting adds a few flipped bits).
struct World {
  std::vector<Eigen::Vector3d> points;
  cv::Mat descriptors;  // one row per point

  int add(const Eigen::Vector3d& p, const cv::Mat& descriptor) {
    points.push_back(p);
    descriptors.push_back(descriptor);
    return static_cast<int>(points.size()) - 1;
  }
};

/// One world point seen by a camera: exact pixel and depth.
struct Sighting {
  int point = 0;
  double u = 0, v = 0, depth = 0;
};

/// World points in front of the camera (T_cw) and inside the image, `border` pixels from its edge.
inline std::vector<Sighting> visible_points(const World& w, const Eigen::Isometry3d& T_cw,
                                            const PinholeCamera& camera = {}, double border = 8.0) {
  std::vector<Sighting> out;
  for (std::size_t i = 0; i < w.points.size(); ++i) {
    const Eigen::Vector3d pc = T_cw * w.points[i];
    if (pc.z() < 0.3) continue;
    const Eigen::Vector2d uv = camera.project(pc);
    if (!camera.in_image(uv.x(), uv.y(), border)) continue;
    out.push_back({static_cast<int>(i), uv.x(), uv.y(), pc.z()});
  }
  return out;
}

inline Eigen::Matrix3d rotation_deg(double deg, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(deg * M_PI / 180.0, axis.normalized()).toRotationMatrix();
}

/// Camera-from-world pose of a camera at `center` with orientation R_wc.
inline Eigen::Isometry3d pose_cw(const Eigen::Vector3d& center, const Eigen::Matrix3d& R_wc) {
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
  T_wc.linear() = R_wc;
  T_wc.translation() = center;
  return T_wc.inverse();
}

/// How far an estimated camera is from the true one: centre distance (m) and relative rotation (deg).
struct PoseError {
  double m = 0, deg = 0;
};

inline PoseError pose_error(const Eigen::Isometry3d& est_cw, const Eigen::Isometry3d& true_cw) {
  const Eigen::Isometry3d d = est_cw * true_cw.inverse();
  return {(est_cw.inverse().translation() - true_cw.inverse().translation()).norm(),
          Eigen::AngleAxisd(d.rotation()).angle() * 180.0 / M_PI};
}

}  // namespace varslam::slam::synthetic
