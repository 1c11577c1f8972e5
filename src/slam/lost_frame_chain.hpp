#pragma once
// While tracking is lost in a map this session did not build, the frames since the loss are chained to each other
// by visual odometry: descriptor matches between consecutive frames, then a rigid RANSAC on their depth. Two uses:
// - relocalization matches the points of several of these frames at once, where one frame sees too little of the
//   map (the frames used, "views", are spaced by camera motion so each adds a viewpoint);
// - once a frame is located, the frames before it are placed back from it along the chain.
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <opencv2/core.hpp>
#include <vector>

#include "slam/frame.hpp"
#include "slam/keyframe_localization.hpp"

namespace varslam::slam {

struct LostFrameChainConfig {
  int max_views = 6;               // views whose points are matched together (the newest ones); 0: none
  double view_spacing_m = 0.01;    // a frame becomes a view when it moved this far from the newest view...
  double view_spacing_deg = 1.0;   // ...or turned this much
  int min_odometry_inliers = 20;   // fewer between two frames: the chain breaks and starts again at the newer one
  std::size_t max_length = 300;    // frames kept for placing back (the oldest are dropped beyond it)
};

class LostFrameChain {
 public:
  explicit LostFrameChain(const LostFrameChainConfig& cfg = {}) : cfg_(cfg) {}

  struct Added {
    bool chained = false;   // located against the previous frame (false: the chain starts again at this frame)
    bool new_view = false;  // the frame became a view
  };
  /// Adds the newest frame. `record` is the caller's index of the frame (what placing back refers to).
  Added add(std::size_t record, std::shared_ptr<const FrameFeatures> features);
  void clear();
  std::size_t length() const { return links_.size(); }
  std::size_t views() const { return views_.size(); }

  /// The views' keypoints with depth, in the newest frame's camera coordinates.
  CameraPoints view_points() const;

  /// Each chained frame (oldest first): its record and its pose relative to the newest frame, T_c_newest.
  struct Placement {
    std::size_t record;
    Eigen::Isometry3d T_c_newest;
  };
  std::vector<Placement> placements() const;

 private:
  struct Link {
    std::size_t record;
    std::shared_ptr<const FrameFeatures> features;  // only while a view or the newest frame
    Eigen::Isometry3d T_anchor_c;  // the frame's pose in the chain's first frame
  };
  bool is_new_view(const Eigen::Isometry3d& T_anchor_c) const;
  void release_unused_features();

  LostFrameChainConfig cfg_;
  std::vector<Link> links_;
  std::vector<std::size_t> views_;  // indices into links_, oldest first
};

/// Rigid pose of frame b in frame a's camera coordinates (T_a_b) from descriptor matches between their keypoints
/// with depth; empty when fewer than `min_inliers` agree. `seed` makes the RANSAC deterministic.
std::optional<Eigen::Isometry3d> relative_pose_by_depth(const FrameFeatures& a, const FrameFeatures& b,
                                                        int min_inliers, std::uint64_t seed);

}  // namespace varslam::slam
