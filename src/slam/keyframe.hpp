#pragma once
// A keyframe: a frame kept in the map. Owns its pose (guarded), its keypoint-to-map-point associations
// (guarded), and its place in the covisibility graph and spanning tree (guarded).
#include <Eigen/Geometry>
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <vector>

#include "slam/dense_alignment.hpp"
#include "slam/frame.hpp"
#include "slam/id_order.hpp"
#include "slam/map_point.hpp"

namespace varslam::slam {

class KeyFrame : public std::enable_shared_from_this<KeyFrame> {
 public:
  KeyFrame(long id, const Frame& frame);

  long id() const { return id_; }
  long frame_id() const { return frame_id_; }
  /// The map segment it belongs to (1 = the first initialisation; a new one after each reinitialisation).
  int segment() const { return segment_; }
  void set_segment(int segment) { segment_ = segment; }
  double timestamp() const { return timestamp_; }
  const FrameFeatures& features() const { return *features_; }
  const std::shared_ptr<const FrameFeatures>& features_ptr() const { return features_; }
  /// Its depth at a quarter of the resolution with movers left out, for dense alignment; empty unless the pipeline
  /// keeps it (loop.final_dense_refine), and for keyframes loaded from a map file.
  DepthSample depth_sample() const;
  void set_depth_sample(DepthSample sample);

  Eigen::Isometry3d pose() const;  // T_cw
  Eigen::Isometry3d pose_inverse() const;  // T_wc
  Eigen::Vector3d camera_center() const;
  void set_pose(const Eigen::Isometry3d& T_cw);
  /// Pose for trajectory output: a culled keyframe follows its parent through the relative pose it had when
  /// it was culled, so frames anchored to it still move with later corrections.
  Eigen::Isometry3d resolved_pose() const;

  // Map point associations (index = keypoint index).
  std::vector<MapPointPtr> map_points() const;
  MapPointPtr map_point(int idx) const;
  void add_map_point(const MapPointPtr& mp, int idx);
  void erase_map_point(int idx);
  void erase_map_point(const MapPoint* mp);
  void replace_map_point(int idx, const MapPointPtr& mp);
  /// Map points (not bad) seen by at least min_obs keyframes.
  int tracked_map_points(int min_obs) const;

  // Covisibility graph.
  void update_connections();
  void add_connection(const std::shared_ptr<KeyFrame>& kf, int weight);
  void erase_connection(const std::shared_ptr<KeyFrame>& kf);
  std::vector<std::shared_ptr<KeyFrame>> covisibles() const;               // by weight, descending
  std::vector<std::shared_ptr<KeyFrame>> best_covisibles(std::size_t n) const;
  std::vector<std::shared_ptr<KeyFrame>> covisibles_with_weight(int min_weight) const;
  int weight(const std::shared_ptr<KeyFrame>& kf) const;

  // Spanning tree.
  std::shared_ptr<KeyFrame> parent() const;
  std::set<std::shared_ptr<KeyFrame>, IdLess> children() const;
  void add_child(const std::shared_ptr<KeyFrame>& kf);
  void erase_child(const std::shared_ptr<KeyFrame>& kf);
  void change_parent(const std::shared_ptr<KeyFrame>& kf);
  /// A loaded map's graph as it was saved: covisibility edges and spanning-tree parent (null for a root).
  void restore_graph(const std::vector<std::pair<std::shared_ptr<KeyFrame>, int>>& connections,
                     const std::shared_ptr<KeyFrame>& parent);
  /// Covisibility edges with their weights, heaviest first.
  std::vector<std::pair<std::shared_ptr<KeyFrame>, int>> connections() const;

  /// Detaches the keyframe from its points and the graph, reconnecting its children; never the first one.
  void set_bad();
  bool is_bad() const { return bad_.load(); }
  /// Drops every graph reference (connections, parent, children): breaks shared_ptr cycles at shutdown.
  void clear_graph();
  void set_not_erase(bool v) { not_erase_ = v; }

  /// Median depth of its map points in this camera (for triangulation baselines).
  double median_depth() const;

  // Local mapping / tracking scratch.
  long local_for_frame = -1;
  long ba_local_for_kf = -1;
  long ba_fixed_for_kf = -1;

 private:
  const long id_;
  const long frame_id_;
  const double timestamp_;
  int segment_ = 1;  // set once, before the keyframe is shared
  std::shared_ptr<const FrameFeatures> features_;

  mutable std::mutex depth_mutex_;
  DepthSample depth_sample_;

  mutable std::mutex pose_mutex_;
  Eigen::Isometry3d T_cw_;
  Eigen::Isometry3d T_c_parent_ = Eigen::Isometry3d::Identity();  // set when culled

  mutable std::mutex features_mutex_;
  std::vector<MapPointPtr> map_points_;

  mutable std::mutex graph_mutex_;
  std::map<std::shared_ptr<KeyFrame>, int, IdLess> connections_;
  std::vector<std::shared_ptr<KeyFrame>> ordered_covisibles_;
  std::vector<int> ordered_weights_;
  std::shared_ptr<KeyFrame> parent_;
  std::set<std::shared_ptr<KeyFrame>, IdLess> children_;
  bool first_connection_ = true;

  std::atomic<bool> bad_{false};
  std::atomic<bool> not_erase_{false};

  void sort_connections_locked();
  void choose_first_parent(const std::vector<std::shared_ptr<KeyFrame>>& heaviest_first);
};

using KeyFramePtr = std::shared_ptr<KeyFrame>;

}  // namespace varslam::slam
