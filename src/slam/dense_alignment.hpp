#pragma once
// Dense depth alignment between two keyframes: projective point-to-plane ICP on their depth images, kept at a
// quarter of the resolution. Sparse map points tie keyframes that share points; two keyframes that see the same
// surface seconds apart through different points are tied by nothing, and the drift between them stays. Their
// depth images still overlap, and ICP measures their relative pose from that overlap.
#include <optional>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/camera.hpp"

namespace varslam::slam {

/// Depth (metres, CV_32FC1) every `step`-th pixel in both directions, in millimetres (CV_16UC1, 0 = none); empty
/// for an empty or non-float image.
cv::Mat depth_mm_every(const cv::Mat& depth_m, int step);

/// A keyframe's depth every kStep-th pixel in both directions, in millimetres (CV_16UC1, 0 = none): ~38 kB a
/// keyframe at 640 x 480. Each sample is the mean of the pixels within kWindow of its pixel whose depth is within
/// 2 % + 5 mm of that pixel's: per-pixel sensor noise drops, while an average never reaches across a depth edge
/// (that would invent a surface). A pixel without depth stays without, and so does one the mover mask covers.
struct DepthSample {
  static constexpr int kStep = 4;
  static constexpr int kWindow = 2;  // a 5 x 5 neighbourhood centred on the sampled pixel
  cv::Mat depth_mm;
  /// `mover_mask`: CV_8UC1 of the depth's size, non-zero where something moved (left out); may be empty.
  static DepthSample of(const cv::Mat& depth_m, const cv::Mat& mover_mask = cv::Mat());
  bool empty() const { return depth_mm.empty(); }
};

/// Points and normals of a depth sample in its camera's frame (metres); a pixel without a smooth neighbourhood
/// (no depth, or a neighbour off by more than 3 % + 1 cm) has a zero normal and is not used.
struct Surface {
  cv::Mat points, normals;  // CV_32FC3, the sample's size
  PinholeCamera camera;     // the sample's intrinsics (the full camera scaled by 1 / kStep)
};
Surface surface_of(const DepthSample& sample, const PinholeCamera& full_camera);

struct DenseAlignConfig {
  int iterations = 15;
  int first_gate_iterations = 5;  // iterations with the wide gate at most
  double first_gate_m = 0.05;     // point-to-plane distance beyond which a pair is dropped, first iterations
  double final_gate_m = 0.02;     // ... then
  double settled_step = 1e-5;     // an update smaller than this (radians and metres) ends a gate's iterations
  double huber_m = 0.005;         // residuals beyond this are down-weighted (Huber)
  int min_pairs = 300;            // fewer matched points: no alignment
};

struct DenseAlignment {
  Eigen::Isometry3d T_target_source;  // maps source camera coordinates into the target camera's
  double overlap = 0;                 // share of the source's points matched at the last iteration
  double rms_m = 0;                   // point-to-plane rms of the matched points
};

/// Aligns `source` to `target` from the guess; nullopt when too few points match.
std::optional<DenseAlignment> align_surfaces(const Surface& target, const Surface& source,
                                             const Eigen::Isometry3d& T_target_source_guess,
                                             const DenseAlignConfig& cfg = {});

}  // namespace varslam::slam
