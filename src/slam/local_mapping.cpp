#include "slam/local_mapping.hpp"

#include <spdlog/spdlog.h>

#include <Eigen/SVD>
#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include "core/elapsed.hpp"
#include "optim/local_ba.hpp"
#include "slam/ba_problem_builder.hpp"
#include "slam/matcher.hpp"

namespace varslam::slam {

namespace {
using Clock = std::chrono::steady_clock;

/// Linear (DLT) triangulation from two camera-from-world poses and normalised image coordinates.
bool triangulate_dlt(const Eigen::Isometry3d& T1, const Eigen::Isometry3d& T2, const Eigen::Vector2d& x1,
                     const Eigen::Vector2d& x2, Eigen::Vector3d& out) {
  const Eigen::Matrix<double, 3, 4> P1 = T1.matrix().topRows<3>();
  const Eigen::Matrix<double, 3, 4> P2 = T2.matrix().topRows<3>();
  Eigen::Matrix4d A;
  A.row(0) = x1.x() * P1.row(2) - P1.row(0);
  A.row(1) = x1.y() * P1.row(2) - P1.row(1);
  A.row(2) = x2.x() * P2.row(2) - P2.row(0);
  A.row(3) = x2.y() * P2.row(2) - P2.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d h = svd.matrixV().col(3);
  if (std::abs(h(3)) < 1e-12) return false;
  out = h.head<3>() / h(3);
  return out.allFinite();
}

}  // namespace

LocalMapper::LocalMapper(const MappingConfig& cfg, Map& map, std::shared_ptr<const ScaleInfo> scale, double close_depth)
    : cfg_(cfg), map_(map), scale_(std::move(scale)), close_depth_(close_depth) {}

LocalMapper::~LocalMapper() { stop(); }

bool LocalMapper::accepts_keyframes() const { return !failed_.load() && !busy_.load() && queued() == 0; }

std::exception_ptr LocalMapper::failure() const {
  std::lock_guard lock(queue_mutex_);
  return failure_;
}

std::size_t LocalMapper::queued() const {
  std::lock_guard lock(queue_mutex_);
  return queue_.size();
}

void LocalMapper::insert(const KeyFramePtr& kf) {
  {
    std::lock_guard lock(queue_mutex_);
    queue_.push_back(kf);
  }
  abort_ba_ = true;
  queue_cv_.notify_one();
}

void LocalMapper::process_all() {
  if (failed_) return;
  for (;;) {
    KeyFramePtr kf;
    {
      std::lock_guard lock(queue_mutex_);
      if (queue_.empty()) return;
      kf = queue_.front();
      queue_.pop_front();
    }
    try {
      process(kf);
    } catch (...) {
      fail(std::current_exception());
      throw;
    }
  }
}

void LocalMapper::fail(std::exception_ptr error) {
  std::lock_guard lock(queue_mutex_);
  failure_ = std::move(error);
  failed_ = true;
  queue_.clear();
  busy_ = false;
  idle_cv_.notify_all();
}

void LocalMapper::start() {
  if (thread_.joinable()) return;
  stop_requested_ = false;
  thread_ = std::thread([this] { run(); });
}

void LocalMapper::stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lock(queue_mutex_);  // else the thread may test the flag, miss the notify and sleep forever
    stop_requested_ = true;
  }
  queue_cv_.notify_all();
  thread_.join();
}

void LocalMapper::pause() {
  std::unique_lock lock(queue_mutex_);
  paused_ = true;
  idle_cv_.wait(lock, [&] { return !busy_.load(); });
}

bool LocalMapper::idle() const {
  std::lock_guard lock(queue_mutex_);
  return !busy_.load() && queue_.empty();
}

void LocalMapper::resume() {
  {
    std::lock_guard lock(queue_mutex_);
    paused_ = false;
  }
  queue_cv_.notify_all();
}

void LocalMapper::run() {
  for (;;) {
    KeyFramePtr kf;
    {
      std::unique_lock lock(queue_mutex_);
      queue_cv_.wait(lock, [&] { return stop_requested_ || (!paused_ && !queue_.empty()); });
      if (queue_.empty()) return;  // stop requested and nothing left
      kf = queue_.front();
      queue_.pop_front();
      busy_ = true;
    }
    try {
      process(kf);
    } catch (...) {
      fail(std::current_exception());  // reaches the caller through failure(); mapping stops here
      return;
    }
    {
      std::lock_guard lock(queue_mutex_);
      busy_ = false;
    }
    idle_cv_.notify_all();
  }
}

void LocalMapper::process(const KeyFramePtr& kf) {
  const auto t0 = Clock::now();
  abort_ba_ = false;
  current_ = KeyframeMapped{};
  current_.keyframe_id = kf->id();
  current_.timestamp = kf->timestamp();
  add_observations(kf);
  cull_recent_points(kf);
  triangulate(kf);
  if (queued() == 0) fuse_neighbours(kf);
  if (queued() == 0) {
    local_ba(kf);
    if (cfg_.cull_keyframes) cull_keyframes(kf);
  } else {
    current_.ba_skipped = true;
  }
  remove_bad_from_map();
  current_.ms = ms_since(t0);
  if (observer_) observer_->on_keyframe_mapped(current_);
  if (keyframe_done_) keyframe_done_(kf);
}

void LocalMapper::add_observations(const KeyFramePtr& kf) {
  const auto points = kf->map_points();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const MapPointPtr& mp = points[i];
    if (!mp || mp->is_bad()) continue;
    if (mp->index_in(kf.get()) < 0) {
      mp->add_observation(kf, static_cast<int>(i), kf->features().has_depth(i));
      mp->update_normal_and_depth(scale_->scale_factors);
      mp->compute_descriptor();
    } else {
      recent_points_.push_back(mp);  // created by tracking for this keyframe
    }
  }
  kf->update_connections();
}

void LocalMapper::cull_recent_points(const KeyFramePtr& kf) {
  constexpr int kMinObservations = 3;  // RGB-D: a point needs support beyond its creating keyframe
  int culled = 0;
  for (auto it = recent_points_.begin(); it != recent_points_.end();) {
    const MapPointPtr& mp = *it;
    const long age = kf->id() - mp->first_keyframe_id();
    if (mp->is_bad()) {
      it = recent_points_.erase(it);
    } else if (mp->moving() || mp->found_ratio() < cfg_.min_found_ratio || (age >= 2 && mp->num_observations() <= kMinObservations)) {
      mp->set_bad();
      ++culled;
      it = recent_points_.erase(it);
    } else if (age >= 3) {
      it = recent_points_.erase(it);
    } else {
      ++it;
    }
  }
  current_.culled_points += culled;
}

void LocalMapper::triangulate(const KeyFramePtr& kf) {
  const FrameFeatures& A = kf->features();
  const ScaleInfo& S = *scale_;
  const Eigen::Isometry3d T1 = kf->pose();
  const Eigen::Isometry3d T1_inv = T1.inverse();
  const Eigen::Vector3d C1 = T1_inv.translation();
  const double baseline = A.camera.bf / A.camera.fx;
  // A point's distances from the two keyframes must agree with the scales it was seen at, within this factor.
  const double ratio_factor = 1.5 * S.scale_factor;
  const auto normalized = [&](const cv::KeyPoint& kp) {
    return Eigen::Vector2d((kp.pt.x - A.camera.cx) / A.camera.fx, (kp.pt.y - A.camera.cy) / A.camera.fy);
  };
  int created = 0;
  for (const auto& nb : kf->best_covisibles(static_cast<std::size_t>(cfg_.triangulation_neighbours))) {
    if (queued() > 0 && created > 0) break;
    const Eigen::Isometry3d T2 = nb->pose();
    const Eigen::Isometry3d T2_inv = T2.inverse();
    const Eigen::Vector3d C2 = T2_inv.translation();
    if ((C2 - C1).norm() < baseline) continue;
    const FrameFeatures& B = nb->features();
    for (const auto& [i1, i2] : match_for_triangulation(*kf, *nb)) {
      const cv::KeyPoint& k1 = A.keypoints[i1];
      const cv::KeyPoint& k2 = B.keypoints[i2];
      const Eigen::Vector2d x1 = normalized(k1), x2 = normalized(k2);
      const Eigen::Vector3d r1 = T1_inv.rotation() * x1.homogeneous();
      const Eigen::Vector3d r2 = T2_inv.rotation() * x2.homogeneous();
      const double cos_parallax = r1.dot(r2) / (r1.norm() * r2.norm());
      constexpr double kMaxCosParallax = 0.9998;  // about a degree of parallax: less triangulates depth noise
      if (cos_parallax <= 0 || cos_parallax > kMaxCosParallax) continue;
      Eigen::Vector3d pw;
      if (!triangulate_dlt(T1, T2, x1, x2, pw)) continue;
      const Eigen::Vector3d p1 = T1 * pw, p2 = T2 * pw;
      if (p1.z() <= 0 || p2.z() <= 0) continue;
      const auto reproj_ok = [&](const Eigen::Vector3d& pc, const cv::KeyPoint& kp) {
        const Eigen::Vector2d uv = A.camera.project(pc);
        const double e2 = (uv - Eigen::Vector2d(kp.pt.x, kp.pt.y)).squaredNorm();
        return e2 <= optim::kChi2Mono * S.level_sigma2[kp.octave];
      };
      if (!reproj_ok(p1, k1) || !reproj_ok(p2, k2)) continue;
      const double d1 = (pw - C1).norm(), d2 = (pw - C2).norm();
      if (d1 == 0 || d2 == 0) continue;
      const double ratio_dist = d2 / d1;
      const double ratio_octave = S.scale_factors[k1.octave] / S.scale_factors[k2.octave];
      if (ratio_dist * ratio_factor < ratio_octave || ratio_dist > ratio_octave * ratio_factor) continue;
      if (kf->map_point(i1) || nb->map_point(i2)) continue;
      auto mp = std::make_shared<MapPoint>(map_.next_map_point_id(), pw, kf);
      mp->add_observation(kf, i1, A.has_depth(i1));
      mp->add_observation(nb, i2, B.has_depth(i2));
      kf->add_map_point(mp, i1);
      nb->add_map_point(mp, i2);
      mp->compute_descriptor();
      mp->update_normal_and_depth(S.scale_factors);
      map_.add_map_point(mp);
      recent_points_.push_back(mp);
      ++created;
    }
  }
  current_.triangulated_points += created;
}

void LocalMapper::fuse_neighbours(const KeyFramePtr& kf) {
  std::vector<KeyFramePtr> targets;
  std::set<long> seen{kf->id()};
  for (const auto& n : kf->best_covisibles(10)) {
    if (n->is_bad() || !seen.insert(n->id()).second) continue;
    targets.push_back(n);
    for (const auto& n2 : n->best_covisibles(5))
      if (!n2->is_bad() && seen.insert(n2->id()).second) targets.push_back(n2);
  }
  const std::vector<MapPointPtr> own = kf->map_points();
  for (const auto& t : targets) fuse_into_keyframe(t, own);

  std::vector<MapPointPtr> candidates;
  std::set<long> cand_ids;
  for (const auto& t : targets)
    for (const auto& mp : t->map_points())
      if (mp && !mp->is_bad() && cand_ids.insert(mp->id()).second) candidates.push_back(mp);
  fuse_into_keyframe(kf, candidates);

  for (const auto& mp : kf->map_points())
    if (mp && !mp->is_bad()) {
      mp->compute_descriptor();
      mp->update_normal_and_depth(scale_->scale_factors);
    }
  kf->update_connections();
}

void LocalMapper::local_ba(const KeyFramePtr& kf) {
  const auto t0 = Clock::now();
  // Local window: the keyframe and its covisibles; fixed: others that see the window's points.
  std::vector<KeyFramePtr> local{kf};
  kf->ba_local_for_kf = kf->id();
  for (const auto& n : kf->best_covisibles(static_cast<std::size_t>(cfg_.max_ba_keyframes - 1)))
    if (!n->is_bad()) {
      n->ba_local_for_kf = kf->id();
      local.push_back(n);
    }
  std::vector<MapPointPtr> points;
  for (const auto& k : local)
    for (const auto& mp : k->map_points()) {
      if (!mp || mp->is_bad() || mp->ba_local_kf == kf->id()) continue;
      mp->ba_local_kf = kf->id();
      // A point tracking saw moving with a near mover is no structure: cull it before BA can lean on it.
      if (mp->moving()) {
        mp->set_bad();
        ++current_.culled_points;
        continue;
      }
      points.push_back(mp);
    }
  // Fixed keyframes: the ones seeing most of the window's points, capped like the window itself (in a small
  // room every keyframe sees the window, and each would add residuals without adding much constraint).
  std::map<KeyFramePtr, int, IdLess> fixed_count;
  for (const auto& mp : points)
    for (const auto& [k, idx] : mp->observations())
      if (k->ba_local_for_kf != kf->id() && !k->is_bad()) fixed_count[k]++;
  std::vector<std::pair<int, KeyFramePtr>> by_count;
  for (const auto& [k, c] : fixed_count) by_count.emplace_back(c, k);
  std::stable_sort(by_count.begin(), by_count.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<KeyFramePtr> fixed;
  for (const auto& [c, k] : by_count) {
    if (fixed.size() >= static_cast<std::size_t>(cfg_.max_ba_keyframes)) break;
    k->ba_fixed_for_kf = kf->id();
    fixed.push_back(k);
  }
  if (local.size() < 2 && fixed.empty()) return;  // nothing anchors the gauge yet

  BaProblemBuilder ba;
  // The first keyframe of the map anchors the gauge when it is in the window.
  for (const auto& k : local) ba.add_keyframe(k, k->id() == 0);
  for (const auto& k : fixed) ba.add_keyframe(k, true);
  for (const auto& mp : points) ba.add_point(mp);
  optim::BaProblem& problem = ba.problem;
  bool any_free = false;
  for (const auto& k : problem.keyframes) any_free |= !k.fixed;
  if (!any_free || problem.observations.empty()) return;

  optim::BaConfig bc;
  bc.kernel = cfg_.kernel;
  bc.outer_iterations = cfg_.ba_outer_iterations;
  bc.iterations = cfg_.ba_iterations;
  bc.refine_iterations = cfg_.ba_refine_iterations;
  bc.solver = cfg_.ba_solver;
  if (running()) bc.stop = &abort_ba_;  // on the mapping thread a newer keyframe ends the solve; never in deterministic mode
  bc.observer = cfg_.ba_observer;
  const PinholeCamera& cam = kf->features().camera;
  optim::BaResult res = optim::solve_local_ba(cam, problem, bc);
  std::vector<Eigen::Isometry3d> before;
  for (const auto& k : ba.keyframes) before.push_back(k->pose());
  if (spdlog::should_log(spdlog::level::debug)) {
    // Large moves of a keyframe away from its tracked pose are how a bad Local BA shows (see mapping.alpha_max).
    const optim::KeyframeObservationCounts counts =
        optim::count_keyframe_observations(problem, res.outlier_observation);
    for (std::size_t i = 0; i < problem.keyframes.size(); ++i) {
      const double moved =
          (problem.keyframes[i].T_cw.inverse().translation() - before[i].inverse().translation()).norm();
      if (!problem.keyframes[i].fixed && moved > 0.03)
        spdlog::debug("Local BA for keyframe {}: keyframe {} moved {:.3f} m, {} of {} observations flagged", kf->id(),
                      ba.keyframes[i]->id(), moved, counts.flagged[i], counts.total[i]);
    }
  }
  for (const int i : optim::keep_diverged_keyframes(problem, before, res.outlier_observation))
    spdlog::debug("Local BA for keyframe {}: keyframe {} diverged (most observations outliers), kept as tracked",
                  kf->id(), ba.keyframes[static_cast<std::size_t>(i)]->id());

  int outliers = 0;
  {
    // Write back under the map's update lock: tracking never sees a half-updated window.
    std::unique_lock lock(map_.update_mutex());
    ba.write_back();
    outliers = ba.erase_outliers(res.outlier_observation);
  }
  for (const auto& mp : points)
    if (!mp->is_bad()) mp->update_normal_and_depth(scale_->scale_factors);

  BaRecord rec;
  rec.keyframe_id = kf->id();
  rec.timestamp = kf->timestamp();
  rec.keyframes = static_cast<int>(local.size());
  rec.fixed_keyframes = static_cast<int>(fixed.size());
  rec.points = static_cast<int>(points.size());
  rec.observations = static_cast<int>(problem.observations.size());
  rec.outliers = outliers;
  rec.alpha_per_iteration = res.alpha_per_iteration;
  // The alpha of the last alternation before the chi2 gate is the one that saw the movers; the refine solve
  // re-fits on the gated inliers, which are near-Gaussian by construction.
  rec.final_alpha = rec.fitted_alpha = res.final_alpha;
  if (!res.alpha_per_iteration.empty()) {
    const std::size_t last = std::min<std::size_t>(res.alpha_per_iteration.size(),
                                                   static_cast<std::size_t>(cfg_.ba_outer_iterations)) - 1;
    rec.final_alpha = res.alpha_per_iteration[last];
    rec.fitted_alpha = res.fitted_alpha_per_iteration[last];
  }
  rec.refine_alpha = res.final_alpha;
  rec.cut_short = res.cut_short;
  rec.ms = ms_since(t0);
  current_.ba = std::move(rec);
}

void LocalMapper::cull_keyframes(const KeyFramePtr& kf) {
  constexpr int kRedundantObservers = 3;
  int culled = 0;
  for (const auto& k : kf->covisibles()) {
    if (k->id() == 0 || k->is_bad()) continue;
    const auto points = k->map_points();
    const FrameFeatures& F = k->features();
    int n_points = 0, n_redundant = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const MapPointPtr& mp = points[i];
      if (!mp || mp->is_bad() || !F.is_close(i)) continue;  // RGB-D: judge by the reliable close points
      ++n_points;
      if (mp->num_observations() <= kRedundantObservers) continue;
      const int level = F.keypoints[i].octave;
      int observers = 0;
      for (const auto& [other, idx] : mp->observations()) {
        if (other == k || other->is_bad()) continue;
        if (other->features().keypoints[idx].octave <= level + 1 && ++observers >= kRedundantObservers) break;
      }
      if (observers >= kRedundantObservers) ++n_redundant;
    }
    if (n_points > 0 && n_redundant > cfg_.keyframe_redundancy * n_points) {
      k->set_bad();
      map_.erase_keyframe(k);
      ++culled;
    }
  }
  current_.culled_keyframes += culled;
}

void LocalMapper::remove_bad_from_map() {
  for (const auto& mp : map_.map_points())
    if (mp->is_bad()) map_.erase_map_point(mp);
  for (const auto& k : map_.keyframes())
    if (k->is_bad()) map_.erase_keyframe(k);
}

}  // namespace varslam::slam
