#include "slam/keyframe.hpp"

#include <algorithm>
#include <set>
#include <utility>
#include <vector>

namespace varslam::slam {

namespace {

constexpr int kCovisibilityMinWeight = 15;  // shared points for a covisibility edge (ORB-SLAM's value)

// Whether `ancestor` is on kf's parent chain; a cycle already in the chain ends the walk.
bool descends_from(const KeyFramePtr& kf, const KeyFrame* ancestor) {
  std::set<const KeyFrame*> seen;
  for (KeyFramePtr k = kf; k && seen.insert(k.get()).second; k = k->parent())
    if (k.get() == ancestor) return true;
  return false;
}

}  // namespace

KeyFrame::KeyFrame(long id, const Frame& frame)
    : id_(id), frame_id_(frame.id), timestamp_(frame.timestamp), features_(frame.features),
      T_cw_(frame.T_cw), map_points_(frame.map_points) {}

DepthSample KeyFrame::depth_sample() const {
  std::lock_guard lock(depth_mutex_);
  return depth_sample_;
}

void KeyFrame::set_depth_sample(DepthSample sample) {
  std::lock_guard lock(depth_mutex_);
  depth_sample_ = std::move(sample);
}

Eigen::Isometry3d KeyFrame::pose() const {
  std::lock_guard lock(pose_mutex_);
  return T_cw_;
}

Eigen::Isometry3d KeyFrame::pose_inverse() const { return pose().inverse(); }

Eigen::Vector3d KeyFrame::camera_center() const { return pose_inverse().translation(); }

void KeyFrame::set_pose(const Eigen::Isometry3d& T_cw) {
  std::lock_guard lock(pose_mutex_);
  T_cw_ = T_cw;
}

Eigen::Isometry3d KeyFrame::resolved_pose() const {
  // Up the chain of culled keyframes to the first live one, one pose lock at a time. The chain is walked, not
  // recursed, and a keyframe met twice ends it: a cycle among culled keyframes must not wait on a held lock.
  Eigen::Isometry3d T_c_k = Eigen::Isometry3d::Identity();
  const KeyFrame* k = this;
  KeyFramePtr hold;  // keeps k alive
  std::vector<const KeyFrame*> visited;
  while (k->is_bad()) {
    visited.push_back(k);
    KeyFramePtr p = k->parent();
    if (!p || std::find(visited.begin(), visited.end(), p.get()) != visited.end()) break;
    {
      std::lock_guard lock(k->pose_mutex_);
      T_c_k = T_c_k * k->T_c_parent_;
    }
    hold = std::move(p);
    k = hold.get();
  }
  return T_c_k * k->pose();
}

std::vector<MapPointPtr> KeyFrame::map_points() const {
  std::lock_guard lock(features_mutex_);
  return map_points_;
}

MapPointPtr KeyFrame::map_point(int idx) const {
  std::lock_guard lock(features_mutex_);
  return map_points_[idx];
}

void KeyFrame::add_map_point(const MapPointPtr& mp, int idx) {
  std::lock_guard lock(features_mutex_);
  map_points_[idx] = mp;
}

void KeyFrame::erase_map_point(int idx) {
  std::lock_guard lock(features_mutex_);
  map_points_[idx].reset();
}

void KeyFrame::erase_map_point(const MapPoint* mp) {
  std::lock_guard lock(features_mutex_);
  for (auto& p : map_points_)
    if (p.get() == mp) p.reset();
}

void KeyFrame::replace_map_point(int idx, const MapPointPtr& mp) { add_map_point(mp, idx); }

int KeyFrame::tracked_map_points(int min_obs) const {
  std::lock_guard lock(features_mutex_);
  int n = 0;
  for (const auto& mp : map_points_)
    if (mp && !mp->is_bad() && (min_obs <= 0 || mp->num_observations() >= min_obs)) ++n;
  return n;
}

void KeyFrame::update_connections() {
  std::map<KeyFramePtr, int, IdLess> counter;
  for (const auto& mp : map_points()) {
    if (!mp || mp->is_bad()) continue;
    for (const auto& [kf, idx] : mp->observations())
      if (kf->id() != id_ && !kf->is_bad()) counter[kf]++;
  }
  if (counter.empty()) return;

  KeyFramePtr best;
  int best_weight = 0;
  for (const auto& [kf, w] : counter) {
    if (w > best_weight) {
      best_weight = w;
      best = kf;
    }
    if (w >= kCovisibilityMinWeight) kf->add_connection(shared_from_this(), w);
  }
  if (best_weight < kCovisibilityMinWeight) best->add_connection(shared_from_this(), best_weight);

  std::vector<KeyFramePtr> parent_candidates;
  {
    std::lock_guard lock(graph_mutex_);
    connections_.clear();
    for (const auto& [kf, w] : counter)
      if (w >= kCovisibilityMinWeight || kf == best) connections_[kf] = w;
    sort_connections_locked();
    if (!first_connection_ || id_ == 0) return;
    parent_candidates = ordered_covisibles_;
  }
  choose_first_parent(parent_candidates);
}

void KeyFrame::choose_first_parent(const std::vector<KeyFramePtr>& heaviest_first) {
  // A keyframe whose first connection came late (it shared no point when inserted) may already be a newer
  // keyframe's parent: taking one of its own descendants would bend the spanning tree into a cycle.
  for (const auto& candidate : heaviest_first) {
    if (descends_from(candidate, this)) continue;
    {
      std::lock_guard lock(graph_mutex_);
      if (!first_connection_) return;
      parent_ = candidate;
      first_connection_ = false;
    }
    candidate->add_child(shared_from_this());
    return;
  }
}

void KeyFrame::add_connection(const KeyFramePtr& kf, int weight) {
  std::lock_guard lock(graph_mutex_);
  auto it = connections_.find(kf);
  if (it != connections_.end() && it->second == weight) return;
  connections_[kf] = weight;
  sort_connections_locked();
}

void KeyFrame::erase_connection(const KeyFramePtr& kf) {
  std::lock_guard lock(graph_mutex_);
  if (connections_.erase(kf)) sort_connections_locked();
}

void KeyFrame::sort_connections_locked() {
  std::vector<std::pair<int, KeyFramePtr>> pairs;
  pairs.reserve(connections_.size());
  for (const auto& [kf, w] : connections_) pairs.emplace_back(w, kf);
  // Heaviest first; ties by id so the order never depends on memory addresses.
  std::stable_sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second->id() < b.second->id();
  });
  ordered_covisibles_.clear();
  ordered_weights_.clear();
  for (const auto& [w, kf] : pairs) {
    ordered_covisibles_.push_back(kf);
    ordered_weights_.push_back(w);
  }
}

std::vector<KeyFramePtr> KeyFrame::covisibles() const {
  std::lock_guard lock(graph_mutex_);
  return ordered_covisibles_;
}

std::vector<KeyFramePtr> KeyFrame::best_covisibles(std::size_t n) const {
  std::lock_guard lock(graph_mutex_);
  const std::size_t k = std::min(n, ordered_covisibles_.size());
  return {ordered_covisibles_.begin(), ordered_covisibles_.begin() + static_cast<long>(k)};
}

std::vector<KeyFramePtr> KeyFrame::covisibles_with_weight(int min_weight) const {
  std::lock_guard lock(graph_mutex_);
  std::vector<KeyFramePtr> out;
  for (std::size_t i = 0; i < ordered_covisibles_.size() && ordered_weights_[i] >= min_weight; ++i)
    out.push_back(ordered_covisibles_[i]);
  return out;
}

int KeyFrame::weight(const KeyFramePtr& kf) const {
  std::lock_guard lock(graph_mutex_);
  auto it = connections_.find(kf);
  return it == connections_.end() ? 0 : it->second;
}

KeyFramePtr KeyFrame::parent() const {
  std::lock_guard lock(graph_mutex_);
  return parent_;
}

std::set<KeyFramePtr, IdLess> KeyFrame::children() const {
  std::lock_guard lock(graph_mutex_);
  return children_;
}

void KeyFrame::add_child(const KeyFramePtr& kf) {
  std::lock_guard lock(graph_mutex_);
  children_.insert(kf);
}

void KeyFrame::erase_child(const KeyFramePtr& kf) {
  std::lock_guard lock(graph_mutex_);
  children_.erase(kf);
}

void KeyFrame::change_parent(const KeyFramePtr& kf) {
  // A keyframe is never its own parent: set_bad() would wait on its own pose lock through it.
  if (!kf || kf.get() == this) return;
  KeyFramePtr old;
  {
    std::lock_guard lock(graph_mutex_);
    old = std::exchange(parent_, kf);
  }
  // The old parent forgets the child, or culling it later would hand the child back a parent (itself, even).
  if (old && old != kf) old->erase_child(shared_from_this());
  kf->add_child(shared_from_this());
}

void KeyFrame::restore_graph(const std::vector<std::pair<KeyFramePtr, int>>& connections, const KeyFramePtr& parent) {
  {
    std::lock_guard lock(graph_mutex_);
    connections_.clear();
    for (const auto& [kf, w] : connections) connections_[kf] = w;
    sort_connections_locked();
    first_connection_ = false;
  }
  if (parent) change_parent(parent);
}

std::vector<std::pair<KeyFramePtr, int>> KeyFrame::connections() const {
  std::lock_guard lock(graph_mutex_);
  std::vector<std::pair<KeyFramePtr, int>> out;
  for (std::size_t i = 0; i < ordered_covisibles_.size(); ++i) out.emplace_back(ordered_covisibles_[i], ordered_weights_[i]);
  return out;
}

void KeyFrame::set_bad() {
  if (id_ == 0 || not_erase_) return;
  if (bad_.exchange(true)) return;
  const auto self = shared_from_this();

  std::map<KeyFramePtr, int, IdLess> connections;
  {
    std::lock_guard lock(graph_mutex_);
    connections = connections_;
  }
  for (const auto& [kf, w] : connections) kf->erase_connection(self);
  for (const auto& mp : map_points())
    if (mp) mp->erase_observation(self);

  // Reconnect the spanning tree: each child takes, among the parent candidates, the most covisible one.
  std::set<KeyFramePtr, IdLess> children;
  KeyFramePtr parent;
  {
    std::lock_guard lock(graph_mutex_);
    children = children_;
    parent = parent_;
  }
  std::set<KeyFramePtr, IdLess> candidates;
  if (parent) candidates.insert(parent);
  while (!children.empty()) {
    KeyFramePtr best_child, best_parent;
    int best_weight = -1;
    for (const auto& child : children) {
      if (child->is_bad()) continue;
      for (const auto& cand : candidates) {
        const int w = child->weight(cand);
        if (w > best_weight) {
          best_weight = w;
          best_child = child;
          best_parent = cand;
        }
      }
    }
    if (!best_child || best_weight <= 0) break;
    best_child->change_parent(best_parent);
    candidates.insert(best_child);
    children.erase(best_child);
  }
  for (const auto& child : children)
    if (parent && child != parent) child->change_parent(parent);
  if (parent) {
    parent->erase_child(self);
    const Eigen::Isometry3d T_parent_w = parent->pose_inverse();  // before taking this one's pose lock
    std::lock_guard lock(pose_mutex_);
    T_c_parent_ = T_cw_ * T_parent_w;
  }

  std::lock_guard lock(graph_mutex_);
  connections_.clear();
  ordered_covisibles_.clear();
  ordered_weights_.clear();
  children_.clear();
}

void KeyFrame::clear_graph() {
  std::lock_guard lock(graph_mutex_);
  connections_.clear();
  ordered_covisibles_.clear();
  ordered_weights_.clear();
  children_.clear();
  parent_.reset();
}

double KeyFrame::median_depth() const {
  const Eigen::Isometry3d T = pose();
  std::vector<double> depths;
  for (const auto& mp : map_points())
    if (mp && !mp->is_bad()) depths.push_back((T * mp->position()).z());
  if (depths.empty()) return 1.0;
  std::nth_element(depths.begin(), depths.begin() + static_cast<long>(depths.size() / 2), depths.end());
  return depths[depths.size() / 2];
}

}  // namespace varslam::slam
