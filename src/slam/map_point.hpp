#pragma once
// A 3-D landmark: position, the keyframes that observe it, and what matching needs to know about it
// (representative descriptor, mean viewing direction, the distance range where its scale is plausible).
#include <Eigen/Core>
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "slam/id_order.hpp"

namespace varslam::slam {

class KeyFrame;
using Observations = std::map<std::shared_ptr<KeyFrame>, int, IdLess>;

class MapPoint {
 public:
  MapPoint(long id, const Eigen::Vector3d& position, const std::shared_ptr<KeyFrame>& reference);
  /// A loaded map's point, with the creation facts it was saved with.
  MapPoint(long id, const Eigen::Vector3d& position, const std::shared_ptr<KeyFrame>& reference, long first_kf_id,
           long first_frame_id);

  long id() const { return id_; }
  long first_keyframe_id() const { return first_kf_id_; }
  long first_frame_id() const { return first_frame_id_; }  // frame of the keyframe that created it

  Eigen::Vector3d position() const;
  void set_position(const Eigen::Vector3d& p);
  Eigen::Vector3d normal() const;
  cv::Mat descriptor() const;  // 1x32 CV_8U (a shared header: do not modify)
  /// For temporary points that have no observation to compute it from.
  void set_descriptor(const cv::Mat& d);

  /// Observations: keyframe -> keypoint index in that keyframe.
  Observations observations() const;
  int num_observations() const;
  void add_observation(const std::shared_ptr<KeyFrame>& kf, int idx, bool has_depth);
  /// Removes one observation; the point turns bad when fewer than two remain.
  void erase_observation(const std::shared_ptr<KeyFrame>& kf);
  int index_in(const KeyFrame* kf) const;  // -1 when not observed by kf
  std::shared_ptr<KeyFrame> reference_keyframe() const;

  /// Marks the point bad and detaches it from every keyframe.
  void set_bad();
  bool is_bad() const { return bad_.load(); }
  /// Makes `other` take this point's observations, then marks this one bad.
  void replace_with(const std::shared_ptr<MapPoint>& other);
  std::shared_ptr<MapPoint> replaced_by() const;

  /// Recomputes the representative descriptor (least median distance to the others).
  void compute_descriptor();
  /// Recomputes mean viewing direction and scale-invariance distances from the observations.
  void update_normal_and_depth(const std::vector<double>& scale_factors);

  /// A loaded map's viewing direction, distance range and tracking counts as they were saved.
  void restore_statistics(const Eigen::Vector3d& normal, double min_distance, double max_distance, int visible,
                          int found);
  /// The tracking counts (visible, found) behind found_ratio().
  int visible() const { return visible_.load(); }
  /// The distance range as computed (min_distance()/max_distance() widen it for matching).
  std::pair<double, double> computed_distance_range() const;

  double min_distance() const;
  double max_distance() const;
  /// Pyramid level at which a point seen at `distance` is expected.
  int predict_scale(double distance, double log_scale_factor, int n_levels) const;

  // Tracking statistics (ratio found/visible drives culling).
  void increase_visible(int n = 1) { visible_.fetch_add(n); }
  void increase_found(int n = 1) { found_.fetch_add(n); }
  int found() const { return found_.load(); }
  /// Frames whose pose optimisation matched the point and flagged it an outlier (what a viewer colours by).
  void increase_flagged() { flagged_.fetch_add(1); }
  int flagged() const { return flagged_.load(); }
  /// Tracking found the point on a mover close to the camera (slam/near_mover.hpp): it is matched no more, Local
  /// BA leaves it out and local mapping culls it.
  void mark_moving() { moving_.store(true); }
  bool moving() const { return moving_.load(); }
  double found_ratio() const { return static_cast<double>(found_.load()) / std::max(1, visible_.load()); }
  /// A point tracking can lean on in frame `frame_id`: a real map point (not a temporary depth point), found as
  /// an inlier in at least `min_found` frames and created at least `min_age` frames before.
  bool is_established(long frame_id, int min_found, int min_age) const {
    return num_observations() > 0 && found() >= min_found && frame_id - first_frame_id_ >= min_age;
  }

  // Per-frame scratch owned by the tracking thread: no other thread reads or writes these two (loop verification
  // matches with LocalMapUse::Verification, which leaves them alone).
  long track_reference_frame = -1;  // last frame id it was added to the local map for
  long last_seen_frame = -1;        // last frame id it was matched in
  long fuse_candidate_kf = -1;      // local mapping scratch (mapping thread, which loop closing runs on)
  long ba_local_kf = -1;            // local mapping scratch (mapping thread)

 private:
  /// Marks the point bad and hands back its observations; nullopt if it already was bad.
  std::optional<Observations> detach(const std::shared_ptr<MapPoint>& replacement);

  const long id_;
  const long first_kf_id_;
  const long first_frame_id_;
  mutable std::mutex mutex_;
  Eigen::Vector3d position_;
  Eigen::Vector3d normal_ = Eigen::Vector3d::Zero();
  cv::Mat descriptor_;
  Observations observations_;
  int n_obs_ = 0;  // counts depth observations as two, like ORB-SLAM's stereo convention
  std::shared_ptr<KeyFrame> reference_;
  std::shared_ptr<MapPoint> replaced_by_;
  double min_distance_ = 0, max_distance_ = 0;
  std::atomic<int> visible_{1}, found_{1}, flagged_{0};
  std::atomic<bool> moving_{false};
  std::atomic<bool> bad_{false};
};

using MapPointPtr = std::shared_ptr<MapPoint>;

}  // namespace varslam::slam
