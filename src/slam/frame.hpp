#pragma once
// A tracked image: its features (immutable once extracted, shared with the keyframe it may become) and the
// per-frame tracking state (pose, matched map points, outlier flags).
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/camera.hpp"
#include "slam/map_point.hpp"

namespace varslam::slam {

class KeyFrame;

/// Scale pyramid facts every stage needs (copied from the extractor).
struct ScaleInfo {
  int n_levels = 8;
  double scale_factor = 1.2;
  double log_scale_factor = 0.0;
  std::vector<double> scale_factors, level_sigma2, inv_level_sigma2;
};

/// Keypoints with depth and descriptors, bucketed on a grid for radius searches.
struct FrameFeatures {
  std::vector<cv::KeyPoint> keypoints;  // undistorted positions, octave = pyramid level
  std::vector<float> depth;             // metres, <= 0 when no valid depth
  std::vector<float> u_right;           // virtual right coordinate u - bf/depth, < 0 when no depth
  cv::Mat descriptors;                  // N x 32, CV_8U
  std::shared_ptr<const ScaleInfo> scale;
  PinholeCamera camera;
  double close_depth = 3.0;  // metres: points closer than this are "close" (reliable depth)
  double disparity_weight = 0.0;  // the depth sensor's noise model for optimisation (optim::Observation)
  int depth_edge_rejected = 0;  // keypoints whose depth was dropped by the depth-edge test
  std::vector<std::uint8_t> on_depth_edge;  // per keypoint: 1 where that test dropped its depth

  static constexpr int kGridCols = 64, kGridRows = 48;
  std::vector<std::vector<int>> grid;  // kGridCols * kGridRows cells of keypoint indices

  std::size_t size() const { return keypoints.size(); }
  bool has_depth(std::size_t i) const { return depth[i] > 0.0f; }
  bool is_close(std::size_t i) const { return depth[i] > 0.0f && depth[i] < close_depth; }
  /// Keypoints within radius r of (u, v) with level in [min_level, max_level] (-1 = unbounded).
  std::vector<int> in_area(double u, double v, double r, int min_level = -1, int max_level = -1) const;
  /// Camera-frame 3-D point of keypoint i from its depth.
  Eigen::Vector3d unproject(std::size_t i) const;
  void build_grid();
};

/// Builds features from keypoints already extracted (and filtered) on `gray`: undistorts keypoint positions,
/// looks up depth at each keypoint, computes u_right. With depth_edge_ratio > 0, a keypoint whose 5x5 depth
/// neighbourhood spans more than that fraction of its depth sits on a depth discontinuity: its depth is
/// dropped (it stays a 2-D observation), since a few pixels of colour/depth misregistration there put the
/// point on the wrong surface.
std::shared_ptr<FrameFeatures> make_frame_features(std::vector<cv::KeyPoint> keypoints, cv::Mat descriptors,
                                                   const cv::Mat& depth_m, const PinholeCamera& camera,
                                                   double close_depth, std::shared_ptr<const ScaleInfo> scale,
                                                   double depth_edge_ratio = 0.0);

/// True when the valid depths in the (2r+1)^2 window around (u, v) span more than ratio * d.
bool on_depth_edge(const cv::Mat& depth_m, int u, int v, float d, double ratio, int r = 2);

struct Frame {
  long id = 0;
  double timestamp = 0.0;
  std::shared_ptr<const FrameFeatures> features;
  Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
  bool has_pose = false;
  std::vector<MapPointPtr> map_points;  // per keypoint, null where unmatched
  std::vector<bool> outlier;
  // Per keypoint: on a mover close to the camera (Tracker's near-mover check); no map point or temporary depth
  // point is made from it.
  std::vector<bool> on_mover;
  std::shared_ptr<KeyFrame> reference_kf;

  Frame() = default;
  Frame(long frame_id, double t, std::shared_ptr<const FrameFeatures> f)
      : id(frame_id), timestamp(t), features(std::move(f)),
        map_points(features->size()), outlier(features->size(), false), on_mover(features->size(), false) {}

  Eigen::Vector3d camera_center() const { return T_cw.inverse().translation(); }
  int num_tracked() const;  // matched, non-outlier, non-bad
  /// Matched, non-outlier map points that are established (MapPoint::is_established) by the found count alone:
  /// the motion-model cross-check was measured this way, before the age rule existed.
  int num_established(int min_found) const;
};

}  // namespace varslam::slam
