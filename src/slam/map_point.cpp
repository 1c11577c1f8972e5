#include "slam/map_point.hpp"

#include <algorithm>
#include <cmath>

#include "features/descriptor_matching.hpp"
#include "slam/keyframe.hpp"

namespace varslam::slam {

MapPoint::MapPoint(long id, const Eigen::Vector3d& position, const std::shared_ptr<KeyFrame>& reference)
    : id_(id), first_kf_id_(reference ? reference->id() : -1), first_frame_id_(reference ? reference->frame_id() : -1),
      position_(position), reference_(reference) {}

MapPoint::MapPoint(long id, const Eigen::Vector3d& position, const std::shared_ptr<KeyFrame>& reference,
                   long first_kf_id, long first_frame_id)
    : id_(id), first_kf_id_(first_kf_id), first_frame_id_(first_frame_id), position_(position), reference_(reference) {}

void MapPoint::restore_statistics(const Eigen::Vector3d& normal, double min_distance, double max_distance, int visible,
                                  int found) {
  {
    std::lock_guard lock(mutex_);
    normal_ = normal;
    min_distance_ = min_distance;
    max_distance_ = max_distance;
  }
  visible_.store(visible);
  found_.store(found);
}

Eigen::Vector3d MapPoint::position() const {
  std::lock_guard lock(mutex_);
  return position_;
}

void MapPoint::set_position(const Eigen::Vector3d& p) {
  std::lock_guard lock(mutex_);
  position_ = p;
}

Eigen::Vector3d MapPoint::normal() const {
  std::lock_guard lock(mutex_);
  return normal_;
}

cv::Mat MapPoint::descriptor() const {
  std::lock_guard lock(mutex_);
  return descriptor_;
}

void MapPoint::set_descriptor(const cv::Mat& d) {
  std::lock_guard lock(mutex_);
  descriptor_ = d.clone();
}

Observations MapPoint::observations() const {
  std::lock_guard lock(mutex_);
  return observations_;
}

int MapPoint::num_observations() const {
  std::lock_guard lock(mutex_);
  return n_obs_;
}

void MapPoint::add_observation(const std::shared_ptr<KeyFrame>& kf, int idx, bool has_depth) {
  std::lock_guard lock(mutex_);
  if (observations_.count(kf)) return;
  observations_[kf] = idx;
  n_obs_ += has_depth ? 2 : 1;
}

void MapPoint::erase_observation(const std::shared_ptr<KeyFrame>& kf) {
  bool now_bad = false;
  {
    std::lock_guard lock(mutex_);
    auto it = observations_.find(kf);
    if (it == observations_.end()) return;
    n_obs_ -= kf->features().has_depth(it->second) ? 2 : 1;
    observations_.erase(it);
    if (reference_ == kf) reference_ = observations_.empty() ? nullptr : observations_.begin()->first;
    now_bad = n_obs_ <= 2;
  }
  if (now_bad) set_bad();
}

int MapPoint::index_in(const KeyFrame* kf) const {
  std::lock_guard lock(mutex_);
  for (const auto& [k, idx] : observations_)
    if (k.get() == kf) return idx;
  return -1;
}

std::shared_ptr<KeyFrame> MapPoint::reference_keyframe() const {
  std::lock_guard lock(mutex_);
  return reference_;
}

std::optional<Observations> MapPoint::detach(const std::shared_ptr<MapPoint>& replacement) {
  Observations obs;
  std::lock_guard lock(mutex_);
  if (bad_.exchange(true)) return std::nullopt;
  obs.swap(observations_);
  n_obs_ = 0;
  reference_.reset();
  replaced_by_ = replacement;
  return obs;
}

void MapPoint::set_bad() {
  const auto obs = detach(nullptr);
  if (!obs) return;
  for (const auto& [kf, idx] : *obs) kf->erase_map_point(idx);
}

void MapPoint::replace_with(const std::shared_ptr<MapPoint>& other) {
  if (other.get() == this) return;
  const auto obs = detach(other);
  if (!obs) return;
  for (const auto& [kf, idx] : *obs) {
    if (other->index_in(kf.get()) < 0) {
      kf->replace_map_point(idx, other);
      other->add_observation(kf, idx, kf->features().has_depth(idx));
    } else {
      kf->erase_map_point(idx);
    }
  }
  other->increase_found(found_.load());
  other->increase_visible(visible_.load());
  other->flagged_.fetch_add(flagged_.load());
  other->compute_descriptor();
}

std::shared_ptr<MapPoint> MapPoint::replaced_by() const {
  std::lock_guard lock(mutex_);
  return replaced_by_;
}

void MapPoint::compute_descriptor() {
  const Observations obs = observations();
  if (obs.empty()) return;
  std::vector<cv::Mat> descs;
  descs.reserve(obs.size());
  for (const auto& [kf, idx] : obs)
    if (!kf->is_bad()) descs.push_back(kf->features().descriptors.row(idx));
  if (descs.empty()) return;
  const int best = medoid_descriptor(descs);
  std::lock_guard lock(mutex_);
  descriptor_ = descs[best].clone();
}

void MapPoint::update_normal_and_depth(const std::vector<double>& scale_factors) {
  Observations obs;
  std::shared_ptr<KeyFrame> ref;
  Eigen::Vector3d pos;
  {
    std::lock_guard lock(mutex_);
    if (bad_ || observations_.empty() || !reference_) return;
    obs = observations_;
    ref = reference_;
    pos = position_;
  }
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& [kf, idx] : obs) {
    const Eigen::Vector3d d = pos - kf->camera_center();
    normal += d.normalized();
    ++n;
  }
  const double dist = (pos - ref->camera_center()).norm();
  const int ref_idx = obs.count(ref) ? obs.at(ref) : obs.begin()->second;
  const int level = ref->features().keypoints[ref_idx].octave;
  const double level_scale = scale_factors[level];
  std::lock_guard lock(mutex_);
  max_distance_ = dist * level_scale;
  min_distance_ = max_distance_ / scale_factors.back();
  normal_ = normal / n;
}

std::pair<double, double> MapPoint::computed_distance_range() const {
  std::lock_guard lock(mutex_);
  return {min_distance_, max_distance_};
}

double MapPoint::min_distance() const {
  std::lock_guard lock(mutex_);
  return 0.8 * min_distance_;
}

double MapPoint::max_distance() const {
  std::lock_guard lock(mutex_);
  return 1.2 * max_distance_;
}

int MapPoint::predict_scale(double distance, double log_scale_factor, int n_levels) const {
  double ratio;
  {
    std::lock_guard lock(mutex_);
    ratio = max_distance_ / std::max(distance, 1e-9);
  }
  const int level = static_cast<int>(std::ceil(std::log(ratio) / log_scale_factor));
  return std::clamp(level, 0, n_levels - 1);
}

}  // namespace varslam::slam
