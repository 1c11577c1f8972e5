#pragma once
// A mover close to the camera, followed from frame to frame once the near-mover check has found it: where it is in
// the image and at which depths. While it is followed, the matches in its region and depth band are suspects: the
// pose is solved without them first, and they count again only where they fit that pose. Suspects that miss it
// confirm that the mover still moves and carry its region along; a mover that stops confirming (a box put down) is
// forgotten after `memory` frames and becomes part of the room again.
//
// Why follow it: once a carried box covers most of the view, the room behind it holds too few matches for the
// check's two depth clusters, and the box's own points (new map points, depth points of the last frame) would pull
// the pose along with it. Followed, they never enter the first solve.
#include <Eigen/Geometry>
#include <utility>
#include <vector>

namespace varslam::slam {

struct MoverTrackConfig {
  int memory = 30;              // frames a mover is followed after it last confirmed (0: not followed)
  float search_margin_px = 64;  // the region grows this much to find the mover in the next frame (it may sweep fast)
  float mark_margin_px = 10;    // ... and this much to mark the keypoints on it
  float depth_margin = 0.15f;   // relative margin of the depth band
  int min_confirming = 20;      // suspects missing the pose to confirm the mover
};

/// Depth band [near, far] (metres) of a mover seen at these depths: around their median, at most `ratio` either way,
/// within their range. One rigid mover lies in a narrow band; the few points of a second mover or of the room among
/// them (a person behind a carried box) stay out of it. {0, 0} when there are no depths.
std::pair<float, float> mover_depth_band(std::vector<float> depths, float ratio = 1.25f);

class MoverTrack {
 public:
  explicit MoverTrack(const MoverTrackConfig& cfg = {}) : cfg_(cfg) {}

  /// Followed at this frame: found or confirmed within the last `memory` frames.
  bool active(long frame_id) const { return cfg_.memory > 0 && seen_ && frame_id - confirmed_frame_ <= cfg_.memory; }
  /// A keypoint at `px` with depth `depth` (metres) may be on the mover: inside the region grown by the search
  /// margin and inside the depth band.
  bool suspect(const Eigen::Vector2f& px, float depth) const { return covers(px, depth, cfg_.search_margin_px); }
  /// Within the depth band and its margin.
  bool in_band(float depth) const;
  /// ... is on the mover: inside the region grown by the (small) marking margin and the depth band.
  bool on_mover(const Eigen::Vector2f& px, float depth) const { return covers(px, depth, cfg_.mark_margin_px); }
  /// The mover was seen moving at these keypoints (image position and depth) in this frame: its region and band
  /// become theirs. Needs at least one point.
  void confirm(long frame_id, const Eigen::AlignedBox2f& region, float near_depth, float far_depth);
  void forget() { seen_ = false; }

  const MoverTrackConfig& config() const { return cfg_; }
  const Eigen::AlignedBox2f& region() const { return region_; }
  float near_depth() const { return near_; }
  float far_depth() const { return far_; }
  long confirmed_frame() const { return confirmed_frame_; }

 private:
  bool covers(const Eigen::Vector2f& px, float depth, float margin_px) const;

  MoverTrackConfig cfg_;
  bool seen_ = false;
  long confirmed_frame_ = 0;
  Eigen::AlignedBox2f region_;
  float near_ = 0, far_ = 0;
};

}  // namespace varslam::slam
