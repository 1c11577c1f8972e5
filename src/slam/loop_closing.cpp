#include "slam/loop_closing.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <set>

#include "core/elapsed.hpp"
#include "optim/local_ba.hpp"
#include "optim/pose_graph.hpp"
#include "slam/ba_problem_builder.hpp"
#include "slam/keyframe_localization.hpp"
#include "slam/matcher.hpp"

namespace varslam::slam {

namespace {
using Clock = std::chrono::steady_clock;

double rotation_deg(const Eigen::Isometry3d& T) {
  return Eigen::AngleAxisd(T.rotation()).angle() * 180.0 / M_PI;
}

/// Frame ids for verification frames: negative and unique per keyframe, so they never collide with the
/// tracker's per-frame scratch marks on map points.
long verification_frame_id(const KeyFrame& kf) { return -2 - kf.id(); }

/// A frame view of a keyframe (its features, no matches) for the localization routines.
Frame frame_of(const KeyFrame& kf) {
  Frame f(verification_frame_id(kf), kf.timestamp(), kf.features_ptr());
  f.T_cw = kf.pose();
  return f;
}

/// World change that moves a keyframe from pose `before` to `after` (p_after = W * p_before).
Eigen::Isometry3d world_change(const Eigen::Isometry3d& before, const Eigen::Isometry3d& after) {
  return after.inverse() * before;
}

/// Keyframes tracking made while a correction was computed (not in `known`) follow the world change `W` of the
/// newest keyframe that was corrected. Call under the map's update lock.
void move_new_keyframes(const Map& map, const std::map<long, Eigen::Isometry3d>& known, const Eigen::Isometry3d& W) {
  for (const auto& k : map.keyframes())
    if (!k->is_bad() && !known.count(k->id())) k->set_pose(k->pose() * W.inverse());
}

}  // namespace

LoopCloser::LoopCloser(const LoopConfig& cfg, const optim::KernelConfig& pose_kernel, Map& map,
                       KeyframeDatabase& places, std::shared_ptr<const ScaleInfo> scale)
    : cfg_(cfg), pose_kernel_(pose_kernel), map_(map), places_(places), scale_(std::move(scale)) {}

std::vector<LoopRecord> LoopCloser::loops() const {
  std::lock_guard lock(records_mutex_);
  return records_;
}

bool LoopCloser::process(const KeyFramePtr& kf) {
  if (kf->is_bad()) return false;
  std::optional<Detection> det;
  if (cfg_.enabled && kf->id() >= last_loop_kf_ + cfg_.keyframes_after_loop &&
      map_.num_keyframes() >= static_cast<std::size_t>(cfg_.min_keyframes)) {
    const auto t_detect = Clock::now();
    det = detect(kf);
    if (observer_) observer_->on_loop_search({kf->id(), ms_since(t_detect)});
  }
  places_.add(kf);
  if (!det) return false;
  const auto t0 = Clock::now();
  LoopRecord rec;
  rec.query_keyframe = kf->id();
  rec.loop_keyframe = det->loop_kf->id();
  rec.timestamp = kf->timestamp();
  rec.score = det->score;
  rec.ransac_inliers = det->ransac_inliers;
  rec.inliers = det->inliers;
  correct(kf, *det, rec);
  rec.total_ms = ms_since(t0);
  spdlog::info("loop closed: keyframe {} (t={:.2f}) with keyframe {}, {} inliers, correction {:.3f} m / {:.2f} deg, "
               "{:.0f} ms",
               rec.query_keyframe, rec.timestamp, rec.loop_keyframe, rec.inliers, rec.correction_m, rec.correction_deg,
               rec.total_ms);
  last_loop_kf_ = kf->id();
  {
    std::lock_guard lock(records_mutex_);
    records_.push_back(rec);
  }
  if (observer_) observer_->on_loop_closed(rec);
  return true;
}

std::optional<LoopCloser::Detection> LoopCloser::detect(const KeyFramePtr& kf) {
  std::set<long> connected{kf->id()};
  for (const auto& c : kf->covisibles()) connected.insert(c->id());
  const long newest_allowed = kf->id() - cfg_.min_keyframe_gap;
  const auto exclude = [&](const KeyFrame& c) { return c.id() > newest_allowed || connected.count(c.id()) > 0; };
  const auto candidates = places_.query(places_.signature(kf->features()), cfg_.min_score, cfg_.candidates, exclude);
  if (!candidates.empty())
    spdlog::debug("keyframe {}: {} connected, {} place candidates, best {} (score {})", kf->id(), connected.size(), candidates.size(),
                  candidates.front().keyframe->id(), candidates.front().score);
  for (const auto& cand : candidates) {
    Detection det;
    if (verify(kf, cand, det)) return det;
  }
  return std::nullopt;
}

bool LoopCloser::verify(const KeyFramePtr& kf, const PlaceCandidate& cand, Detection& out) const {
  Frame f = frame_of(*kf);
  LocalizationConfig lc;
  lc.min_inliers = cfg_.min_ransac_inliers;
  lc.kernel = pose_kernel_;
  const int ransac_inliers = locate_against_keyframe(f, *cand.keyframe, lc);
  if (ransac_inliers == 0) return false;
  // Guided matching against the loop keyframe's neighbourhood, from the pose found.
  std::vector<MapPointPtr> loop_points;
  std::set<long> seen;
  std::vector<KeyFramePtr> loop_group{cand.keyframe};
  for (const auto& n : cand.keyframe->best_covisibles(10)) loop_group.push_back(n);
  for (const auto& g : loop_group)
    for (const auto& mp : g->map_points())
      if (mp && !mp->is_bad() && seen.insert(mp->id()).second) loop_points.push_back(mp);
  match_local_map(f, loop_points, 1.0, LocalMapUse::Verification);
  const int inliers = refine_pose_on_matches(f, pose_kernel_);
  spdlog::debug("loop candidate {} for keyframe {}: score {}, ransac {}, guided inliers {}", cand.keyframe->id(),
                kf->id(), cand.score, ransac_inliers, inliers);
  if (inliers < cfg_.min_inliers) return false;
  if (loop_side_agrees_with_own_pose(kf, loop_points, inliers, f.T_cw)) {
    spdlog::debug("loop candidate {} for keyframe {} rejected: its neighbourhood agrees with the keyframe's own pose, "
                  "the loop pose follows a mover", cand.keyframe->id(), kf->id());
    return false;
  }
  out.loop_kf = cand.keyframe;
  out.score = cand.score;
  out.ransac_inliers = ransac_inliers;
  out.inliers = inliers;
  out.T_cw_corrected = f.T_cw;
  out.matches = f.map_points;
  out.loop_points = std::move(loop_points);
  return true;
}

bool LoopCloser::loop_side_agrees_with_own_pose(const KeyFramePtr& kf, const std::vector<MapPointPtr>& loop_points,
                                                 int loop_inliers, const Eigen::Isometry3d& T_cw_loop) const {
  // The no-loop hypothesis: the same neighbourhood matched from the keyframe's own pose. Drift worth a loop leaves
  // little to match there; when much of the loop side agrees with the own pose, the map is consistent here and the
  // loop pose follows something that moved between the two visits (a box held in front of the camera).
  if (cfg_.max_own_pose_share <= 0) return false;
  Frame g = frame_of(*kf);
  match_local_map(g, loop_points, 1.0, LocalMapUse::Verification);
  const int own_inliers = refine_pose_on_matches(g, pose_kernel_);
  const Eigen::Vector3d refined = g.T_cw.inverse().translation();
  const bool stays_at_own = (kf->camera_center() - refined).norm() < (T_cw_loop.inverse().translation() - refined).norm();
  spdlog::debug("keyframe {}: {} inliers at the loop pose, {} at its own pose", kf->id(), loop_inliers, own_inliers);
  return stays_at_own && own_inliers >= cfg_.max_own_pose_share * loop_inliers;
}

void LoopCloser::correct(const KeyFramePtr& kf, Detection& det, LoopRecord& rec) {
  // Poses before any change: the ordinary pose-graph edges are measured on them.
  std::map<long, Eigen::Isometry3d> uncorrected;
  for (const auto& k : map_.keyframes())
    if (!k->is_bad()) uncorrected[k->id()] = k->pose();
  const Eigen::Isometry3d T_k = kf->pose();
  const Eigen::Isometry3d W = world_change(T_k, det.T_cw_corrected);  // current side -> loop side
  rec.correction_m = (kf->camera_center() - det.T_cw_corrected.inverse().translation()).norm();
  rec.correction_deg = rotation_deg(T_k * det.T_cw_corrected.inverse());

  std::vector<KeyFramePtr> group{kf};
  for (const auto& c : kf->covisibles())
    if (!c->is_bad()) group.push_back(c);
  std::map<long, std::set<long>> connections_before;
  for (const auto& g : group)
    for (const auto& c : g->covisibles()) connections_before[g->id()].insert(c->id());

  {
    // 1. Rigid correction of the query keyframe's neighbourhood and its points, then fusion with the loop side.
    std::unique_lock lock(map_.update_mutex());
    std::set<long> moved;
    for (const auto& g : group) {
      g->set_pose(g->pose() * W.inverse());
      for (const auto& mp : g->map_points())
        if (mp && !mp->is_bad() && moved.insert(mp->id()).second) mp->set_position(W * mp->position());
    }
    int fused = 0;
    const FrameFeatures& F = kf->features();
    for (std::size_t i = 0; i < det.matches.size(); ++i) {
      const MapPointPtr& loop_mp = det.matches[i];
      if (!loop_mp || loop_mp->is_bad()) continue;
      const MapPointPtr own = kf->map_point(static_cast<int>(i));
      if (own == loop_mp) continue;
      if (own && !own->is_bad()) {
        own->replace_with(loop_mp);
      } else if (loop_mp->index_in(kf.get()) < 0) {
        kf->add_map_point(loop_mp, static_cast<int>(i));
        loop_mp->add_observation(kf, static_cast<int>(i), F.has_depth(i));
      }
      ++fused;
    }
    for (const auto& g : group) fused += fuse_into_keyframe(g, det.loop_points);
    rec.fused_points = fused;
    for (const auto& mp : det.loop_points)
      if (!mp->is_bad()) {
        mp->compute_descriptor();
        mp->update_normal_and_depth(scale_->scale_factors);
      }
  }
  // 2. The links the loop created (new covisibility between the two sides) join the pose graph for good.
  std::vector<std::pair<KeyFramePtr, KeyFramePtr>> new_links;
  for (const auto& g : group) {
    g->update_connections();
    const auto& before = connections_before[g->id()];
    for (const auto& c : g->covisibles())
      if (!before.count(c->id()) && std::find(group.begin(), group.end(), c) == group.end()) new_links.emplace_back(g, c);
  }
  if (new_links.empty()) new_links.emplace_back(kf, det.loop_kf);
  for (const auto& l : new_links) loop_links_.push_back(l);
  optimize_pose_graph(kf, new_links, uncorrected, rec);
  if (cfg_.global_ba) global_bundle_adjustment(kf, rec);
}

void LoopCloser::optimize_pose_graph(const KeyFramePtr& kf,
                                     const std::vector<std::pair<KeyFramePtr, KeyFramePtr>>& new_links,
                                     const std::map<long, Eigen::Isometry3d>& uncorrected, LoopRecord& rec) {
  const auto t0 = Clock::now();
  const std::vector<KeyFramePtr> kfs = map_.keyframes();
  optim::PoseGraphProblem pg;
  std::map<long, int> vertex;
  std::map<long, Eigen::Isometry3d> initial;
  for (const auto& k : kfs) {
    if (k->is_bad()) continue;
    vertex[k->id()] = static_cast<int>(pg.T_cw.size());
    initial[k->id()] = k->pose();
    pg.T_cw.push_back(k->pose());
    pg.fixed.push_back(pg.fixed.empty());  // the oldest keyframe holds the gauge
  }
  std::set<std::pair<long, long>> used;
  const auto add_edge = [&](const KeyFramePtr& a, const KeyFramePtr& b, bool measured_now) {
    if (!a || !b || a == b) return;
    auto ia = vertex.find(a->id()), ib = vertex.find(b->id());
    if (ia == vertex.end() || ib == vertex.end()) return;
    const std::pair<long, long> key = std::minmax(a->id(), b->id());  // a copy: minmax returns references
    if (!used.insert(key).second) return;
    const auto pose_of = [&](const KeyFramePtr& k) {
      if (measured_now) return initial.at(k->id());
      auto u = uncorrected.find(k->id());
      return u != uncorrected.end() ? u->second : initial.at(k->id());
    };
    pg.edges.push_back({ia->second, ib->second, pose_of(a) * pose_of(b).inverse(), 1.0});
  };
  // Loop edges first (measured on the corrected poses), then the spanning tree and strong covisibility
  // (measured before the correction: they carry the odometry the loop must bend, not break).
  for (const auto& [a, b] : new_links) add_edge(a, b, true);
  for (const auto& [a, b] : loop_links_) add_edge(a, b, true);
  for (const auto& k : kfs) {
    if (k->is_bad()) continue;
    add_edge(k, k->parent(), false);
    for (const auto& c : k->covisibles_with_weight(cfg_.pose_graph_min_weight)) add_edge(k, c, false);
  }
  optim::PoseGraphConfig pc;
  optim::optimize_pose_graph(pg, pc);

  std::unique_lock lock(map_.update_mutex());
  for (const auto& k : kfs)
    if (!k->is_bad() && vertex.count(k->id())) k->set_pose(pg.T_cw[vertex.at(k->id())]);
  propagate(initial, kf);
  map_.note_correction();
  rec.pose_graph_ms = ms_since(t0);
}

void LoopCloser::propagate(const std::map<long, Eigen::Isometry3d>& before, const KeyFramePtr& anchor) {
  const Eigen::Isometry3d W_anchor = world_change(before.at(anchor->id()), anchor->pose());
  move_new_keyframes(map_, before, W_anchor);
  // Points follow their reference keyframe (or any observer that was optimised); new points follow the anchor.
  for (const auto& mp : map_.map_points()) {
    if (mp->is_bad()) continue;
    KeyFramePtr ref = mp->reference_keyframe();
    if (!ref || ref->is_bad() || !before.count(ref->id())) {
      ref.reset();
      for (const auto& [k, idx] : mp->observations())
        if (!k->is_bad() && before.count(k->id())) {
          ref = k;
          break;
        }
    }
    const Eigen::Isometry3d W = ref ? world_change(before.at(ref->id()), ref->pose()) : W_anchor;
    mp->set_position(W * mp->position());
  }
}

DenseRefinementResult LoopCloser::refine_with_depth() {
  std::vector<KeyFramePtr> kfs;
  for (const auto& k : map_.keyframes())
    if (!k->is_bad()) kfs.push_back(k);
  if (kfs.size() < 2) return {};
  std::map<long, Eigen::Isometry3d> before;
  std::vector<Eigen::Isometry3d> T_cw;
  for (const auto& k : kfs) {
    before[k->id()] = k->pose();
    T_cw.push_back(k->pose());
  }
  const DenseRefinementResult r = refine_poses_with_depth(kfs, kfs.front()->features().camera, T_cw);
  if (r.edges == 0) return r;
  std::unique_lock lock(map_.update_mutex());
  for (std::size_t i = 0; i < kfs.size(); ++i) kfs[i]->set_pose(T_cw[i]);
  propagate(before, kfs.back());
  map_.note_correction();
  return r;
}

double LoopCloser::run_global_ba() {
  const auto kfs = map_.keyframes();
  if (kfs.empty()) return 0;
  LoopRecord rec;
  global_bundle_adjustment(kfs.back(), rec);
  return rec.global_ba_ms;
}

void LoopCloser::global_bundle_adjustment(const KeyFramePtr& kf, LoopRecord& rec) {
  const auto t0 = Clock::now();
  BaProblemBuilder ba;
  for (const auto& k : map_.keyframes())
    if (!k->is_bad()) ba.add_keyframe(k, ba.keyframes.empty());  // the oldest keyframe holds the gauge
  for (const auto& mp : map_.map_points())
    if (!mp->is_bad()) ba.add_point(mp);
  if (ba.keyframes.size() < 2 || ba.problem.observations.empty()) return;
  // Global BA as ORB-SLAM runs it (the paper leaves it unchanged): Huber, one solve, then the chi2 gate.
  optim::BaConfig bc;
  bc.kernel.type = optim::KernelType::Huber;
  bc.outer_iterations = 1;
  bc.iterations = cfg_.global_ba_iterations;
  bc.refine_iterations = cfg_.global_ba_iterations / 2;
  const optim::BaResult res = optim::solve_local_ba(kf->features().camera, ba.problem, bc);

  std::unique_lock lock(map_.update_mutex());
  std::map<long, Eigen::Isometry3d> before;
  for (const auto& k : ba.keyframes) before[k->id()] = k->pose();
  const KeyFramePtr anchor = ba.keyframes.back();
  ba.write_back();
  ba.erase_outliers(res.outlier_observation);
  const Eigen::Isometry3d W_anchor = world_change(before.at(anchor->id()), anchor->pose());
  std::set<long> optimised_points;
  for (const auto& mp : ba.points) optimised_points.insert(mp->id());
  // What tracking added while the solver ran follows the newest optimised keyframe.
  move_new_keyframes(map_, before, W_anchor);
  for (const auto& mp : map_.map_points())
    if (!mp->is_bad() && !optimised_points.count(mp->id())) mp->set_position(W_anchor * mp->position());
  for (const auto& mp : ba.points)
    if (!mp->is_bad()) mp->update_normal_and_depth(scale_->scale_factors);
  map_.note_correction();
  rec.global_ba_ms = ms_since(t0);
}

}  // namespace varslam::slam
