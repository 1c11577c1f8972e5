#pragma once
// Closed-form least-squares alignment of two point sets (Horn / Umeyama via SVD, as the TUM benchmark's
// evaluate_ate does it): find R, t (and optionally a scale s) minimising sum |s R model_i + t - data_i|^2.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace varslam {

struct Alignment {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double scale = 1.0;  // 1 for a rigid (SE(3)) alignment

  Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return scale * (R * p) + t; }
  /// A camera-to-world pose moved into the aligned frame (translation scaled, rotation rotated).
  Eigen::Isometry3d apply(const Eigen::Isometry3d& T) const;
};

/// model and data are 3xN with corresponding columns, N >= 2. with_scale = false gives the rigid
/// alignment of evaluate_ate (RGB-D, stereo); with_scale = true the Sim(3) one (monocular).
/// Throws std::invalid_argument on mismatched sizes or fewer than 2 points.
Alignment align_point_sets(const Eigen::Matrix3Xd& model, const Eigen::Matrix3Xd& data, bool with_scale = false);

}  // namespace varslam
