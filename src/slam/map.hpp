#pragma once
// The map: the set of keyframes and points, with its own narrow lock. The `update_mutex` orders writers
// (Local BA write-back, culling) against the tracker reading many poses and points in one go.
#include <atomic>
#include <memory>
#include <mutex>
#include <set>
#include <shared_mutex>
#include <vector>

#include "slam/id_order.hpp"
#include "slam/keyframe.hpp"
#include "slam/map_point.hpp"

namespace varslam::slam {

class Map {
 public:
  void add_keyframe(const KeyFramePtr& kf);
  void add_map_point(const MapPointPtr& mp);
  void erase_keyframe(const KeyFramePtr& kf);
  void erase_map_point(const MapPointPtr& mp);

  std::vector<KeyFramePtr> keyframes() const;  // ordered by id (deterministic)
  std::vector<MapPointPtr> map_points() const;  // ordered by id
  std::size_t num_keyframes() const;
  std::size_t num_map_points() const;

  long next_keyframe_id() { return next_kf_id_++; }
  /// After loading a saved map: new keyframes and points get ids after the loaded ones.
  void continue_ids(long next_keyframe_id, long next_map_point_id);
  long next_map_point_id() { return next_mp_id_++; }

  /// Breaks the shared_ptr cycles between keyframes and points (call once when done with the map).
  void clear();

  std::shared_mutex& update_mutex() { return update_mutex_; }

  /// Counts map-wide corrections (loop closures): tracking re-anchors its last frame when it changes.
  long corrections() const { return corrections_.load(); }
  void note_correction() { corrections_.fetch_add(1); }

 private:
  mutable std::mutex mutex_;
  std::set<KeyFramePtr, IdLess> keyframes_;
  std::set<MapPointPtr, IdLess> map_points_;
  std::atomic<long> next_kf_id_{0};
  std::atomic<long> next_mp_id_{0};
  std::shared_mutex update_mutex_;
  std::atomic<long> corrections_{0};
};

}  // namespace varslam::slam
