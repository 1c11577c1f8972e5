#include "slam/map.hpp"

#include <algorithm>

namespace varslam::slam {

void Map::add_keyframe(const KeyFramePtr& kf) {
  std::lock_guard lock(mutex_);
  keyframes_.insert(kf);
}

void Map::add_map_point(const MapPointPtr& mp) {
  std::lock_guard lock(mutex_);
  map_points_.insert(mp);
}

void Map::erase_keyframe(const KeyFramePtr& kf) {
  std::lock_guard lock(mutex_);
  keyframes_.erase(kf);
}

void Map::erase_map_point(const MapPointPtr& mp) {
  std::lock_guard lock(mutex_);
  map_points_.erase(mp);
}

std::vector<KeyFramePtr> Map::keyframes() const {
  std::lock_guard lock(mutex_);
  return {keyframes_.begin(), keyframes_.end()};
}

std::vector<MapPointPtr> Map::map_points() const {
  std::lock_guard lock(mutex_);
  return {map_points_.begin(), map_points_.end()};
}

std::size_t Map::num_keyframes() const {
  std::lock_guard lock(mutex_);
  return keyframes_.size();
}

std::size_t Map::num_map_points() const {
  std::lock_guard lock(mutex_);
  return map_points_.size();
}

void Map::clear() {
  std::set<KeyFramePtr, IdLess> kfs;
  std::set<MapPointPtr, IdLess> mps;
  {
    std::lock_guard lock(mutex_);
    kfs.swap(keyframes_);
    mps.swap(map_points_);
  }
  // Setting every point bad drops the keyframe->point and point->keyframe references.
  for (const auto& mp : mps) mp->set_bad();
  for (const auto& kf : kfs) kf->clear_graph();
}

void Map::continue_ids(long next_keyframe_id, long next_map_point_id) {
  next_kf_id_.store(std::max(next_kf_id_.load(), next_keyframe_id));
  next_mp_id_.store(std::max(next_mp_id_.load(), next_map_point_id));
}

}  // namespace varslam::slam
