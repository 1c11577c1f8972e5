#include "slam/tracking.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <unordered_set>
#include <shared_mutex>
#include <utility>

#include "core/elapsed.hpp"
#include "optim/pose_optimizer.hpp"
#include "slam/ba_problem_builder.hpp"
#include "slam/keyframe_localization.hpp"
#include "slam/matcher.hpp"
#include "slam/rolling_shutter.hpp"

namespace varslam::slam {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kMinKeypointsToInitialize = 500;  // enough structure to start a map (ORB-SLAM's rule)
constexpr int kMinInliersMotion = 10;
constexpr int kMinEstablished = 30;  // established matches needed to solve on them first

LostFrameChainConfig lost_chain_config(const RelocalizationConfig& rc) {
  LostFrameChainConfig c;
  c.max_views = rc.lost_views;
  return c;
}

}  // namespace

Tracker::Tracker(const SlamConfig& cfg, const PinholeCamera& camera, double close_depth, Map& map, KeyframeSink& sink)
    : cfg_(cfg), camera_(camera), close_depth_(close_depth), map_(map), sink_(sink),
      extractor_(make_extractor(cfg.orb, cfg.extractor)), mover_track_(cfg.tracking.mover_track),
      lost_chain_(lost_chain_config(cfg.relocalization)) {
  auto s = std::make_shared<ScaleInfo>();
  s->n_levels = extractor_->n_levels();
  s->scale_factor = extractor_->scale_factor();
  s->log_scale_factor = std::log(s->scale_factor);
  s->scale_factors = extractor_->scale_factors();
  s->level_sigma2 = extractor_->level_sigma2();
  s->inv_level_sigma2 = extractor_->inv_level_sigma2();
  scale_ = s;
}

namespace {

// A neighbourhood's loose matches have a low inlier share: 200 RANSAC samples often miss a clean one.
constexpr int kNeighbourhoodRansacIterations = 1000;
// Several views' loose matches to the whole neighbourhood of every candidate: a few percent are right, so a clean
// sample of three is rare (1000 samples found none on the kitchen's reverse start).
constexpr int kLostViewsRansacIterations = 20000;
// Map points the views are matched against, at most (whole neighbourhoods, best candidate first): brute-force matching
// of ~4000 view points costs ~40 ms against 3000 map points and ~200 ms against 20000.
constexpr std::size_t kLostViewsMaxMapPoints = 4000;

// The pixels where keypoints may be taken: those `allowed` (all when empty) that the caller's mover mask leaves.
cv::Mat without_movers(const cv::Mat& allowed, const cv::Mat& movers) {
  cv::Mat out;
  cv::compare(movers, 0, out, cv::CMP_EQ);
  if (!allowed.empty()) cv::bitwise_and(out, allowed, out);
  return out;
}

}  // namespace

Frame Tracker::build_frame(const RgbdFrame& input, FrameTimings& t) {
  auto t0 = Clock::now();
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  cv::Mat mask;
  if (extraction_mask_) mask = extraction_mask_(input);
  if (!input.mover_mask.empty()) mask = without_movers(mask, input.mover_mask);
  if (!mask.empty()) {
    t.filter_ms = ms_since(t0);
    t0 = Clock::now();
  }
  extractor_->extract(input.gray, kps, desc, mask);
  t.extract_ms = ms_since(t0);
  if (filter_ && !kps.empty()) {
    t0 = Clock::now();
    const std::vector<bool> keep = filter_(input, kps);
    std::vector<cv::KeyPoint> kept;
    cv::Mat kept_desc;
    kept.reserve(kps.size());
    for (std::size_t i = 0; i < kps.size(); ++i)
      if (keep[i]) {
        kept.push_back(kps[i]);
        kept_desc.push_back(desc.row(static_cast<int>(i)));
      }
    kps.swap(kept);
    desc = kept_desc;
    t.filter_ms += ms_since(t0);
  }
  const bool rolling = cfg_.tracking.rolling_shutter_s > 0;
  std::vector<float> sensor_rows;
  if (rolling)
    for (const cv::KeyPoint& kp : kps) sensor_rows.push_back(kp.pt.y);
  auto features = make_frame_features(std::move(kps), desc, input.depth, camera_, close_depth_, scale_,
                                      cfg_.tracking.depth_edge_ratio);
  features->disparity_weight = cfg_.tracking.disparity_weight;
  if (rolling) {
    shutter_source_.features = std::make_shared<const FrameFeatures>(*features);
    shutter_source_.sensor_rows = std::move(sensor_rows);
    shutter_source_.image_rows = input.gray.rows;
    if (state_ == TrackState::Ok && velocity_dt_ > 0) compensate_with(*features, velocity_, velocity_dt_);
  }
  return Frame(next_frame_id_++, input.timestamp, std::move(features));
}

void Tracker::compensate_with(FrameFeatures& f, const Eigen::Isometry3d& motion, double dt) const {
  compensate_rolling_shutter(f, shutter_source_.sensor_rows,
                             {cfg_.tracking.rolling_shutter_s, shutter_source_.image_rows}, motion, dt);
}

void Tracker::refine_rolling_shutter(Frame& cur, FrameTimings& t) {
  const double dt = cur.timestamp - last_.timestamp;
  if (!shutter_source_.features || dt <= 0) return;
  // The first solve compensated with the previous interval's velocity; the frame's own motion, now measured, is the
  // better estimate of how the camera moved while its rows were read.
  auto features = std::make_shared<FrameFeatures>(*shutter_source_.features);
  compensate_with(*features, cur.T_cw * last_.T_cw.inverse(), dt);
  cur.features = std::move(features);
  // The pose alone is solved again, on the first solve's inliers: which matches are outliers or on a mover was
  // decided there, and deciding it twice per frame would let the mover follower confirm a mover twice.
  const auto t0 = Clock::now();
  FramePoseProblem p = frame_pose_problem(cur);
  FramePoseProblem inliers;
  for (std::size_t k = 0; k < p.keypoints.size(); ++k) {
    if (cur.outlier[p.keypoints[k]]) continue;
    inliers.points.push_back(p.points[k]);
    inliers.observations.push_back(p.observations[k]);
    inliers.keypoints.push_back(p.keypoints[k]);
  }
  if (inliers.keypoints.size() >= 3) {
    Eigen::Isometry3d T_cw = cur.T_cw;
    const optim::PoseOptimResult res =
        optim::optimize_pose(camera_, T_cw, inliers.points, inliers.observations, pose_config());
    if (res.inliers >= kMinInliersMotion) cur.T_cw = T_cw;
  }
  t.pose_ms += ms_since(t0);
}

TrackOutcome Tracker::track(const RgbdFrame& input) {
  TrackOutcome out;
  const auto t_start = Clock::now();
  Frame cur = build_frame(input, out.timings);
  out.features = cur.features;
  out.keypoint_fate.assign(cur.features->size(), KeypointFate::Unmatched);
  out.keypoints = static_cast<int>(cur.features->size());
  for (std::size_t i = 0; i < cur.features->size(); ++i) out.keypoints_with_depth += cur.features->has_depth(i);
  out.depth_edge_rejected = cur.features->depth_edge_rejected;

  std::shared_lock map_lock(map_.update_mutex());
  if (state_ == TrackState::NotInitialized) {
    if (initialize(cur, Eigen::Isometry3d::Identity())) {
      state_ = TrackState::Ok;
      out.keyframe = true;
    }
    record(cur, state_ == TrackState::Ok);
    out.state = state_;
    if (state_ == TrackState::Ok) out.live_T_wc = cur.T_cw.inverse();
    if (out.keyframe && cur.reference_kf) {
      out.keyframe_id = cur.reference_kf->id();
      out.new_keyframe = cur.reference_kf;
    }
    out.timings.track_ms = ms_since(t_start);
    last_ = cur;
    return out;
  }

  bool ok = false;
  const bool was_tracked = state_ == TrackState::Ok;
  if (was_tracked) {
    refresh_last_frame(cur.id);
    ok = track_initial_pose(cur, out.timings);
  } else {
    refresh_last_frame(cur.id);
    chain_lost_frame(cur, out.timings);
    ok = recover(cur, out.timings);
  }
  if (ok) ok = track_local_map(cur, out.timings);
  if (ok && was_tracked && cfg_.tracking.rolling_shutter_s > 0) {
    refine_rolling_shutter(cur, out.timings);
    out.features = cur.features;
  }

  if (ok) {
    state_ = TrackState::Ok;
    lost_count_ = 0;
    awaiting_loaded_map_ = false;
    pose_hint_.reset();
    if (!was_tracked && cfg_.relocalization.place_back_lost_frames) place_back_chained_frames(cur);
    lost_chain_.clear();
    // After a loss (or before the first fix in a loaded map) the last pose was only predicted: no velocity can be
    // taken from it, and at frame rate standing still is the better guess.
    velocity_ = was_tracked ? cur.T_cw * last_.T_cw.inverse() : Eigen::Isometry3d::Identity();
    velocity_dt_ = was_tracked ? cur.timestamp - last_.timestamp : 0.0;
    has_velocity_ = true;
    clean_temporary_matches(cur);
    record_fates(cur, out);
    out.residuals = inlier_residuals(cur, camera_);
    for (std::size_t i = 0; i < cur.map_points.size(); ++i)
      if (cur.map_points[i] && cur.outlier[i]) cur.map_points[i].reset();
    out.inliers = cur.num_tracked();
    if (need_keyframe(cur, out.inliers)) {
      create_keyframe(cur);
      out.keyframe = true;
    }
    record(cur, true);
  } else {
    // Lost: keep predicting with the motion model; after a few failed recoveries (local, then global
    // relocalization) start a new map segment at the predicted pose so the trajectory goes on. Loop closing
    // can join the segment to the old map when it sees an old place again.
    ++lost_count_;
    state_ = TrackState::Lost;
    cur.T_cw = (has_velocity_ ? velocity_ : Eigen::Isometry3d::Identity()) * last_.T_cw;
    std::fill(cur.map_points.begin(), cur.map_points.end(), nullptr);
    const int patience =
        awaiting_loaded_map_ ? cfg_.relocalization.loaded_map_patience : cfg_.tracking.lost_frames_before_reinit;
    if (!localization_only_ && lost_count_ > patience && initialize(cur, cur.T_cw)) {
      awaiting_loaded_map_ = false;
      lost_chain_.clear();
      spdlog::warn("tracking lost for {} frames at t={:.3f}: new map segment started", lost_count_, cur.timestamp);
      state_ = TrackState::Ok;
      lost_count_ = 0;
      has_velocity_ = false;
      velocity_dt_ = 0;
      out.keyframe = true;
      out.new_segment = true;
      record(cur, true);
    } else {
      cur.reference_kf = reference_kf_;
      record(cur, false);
    }
  }
  out.state = state_;
  if (state_ == TrackState::Ok) out.live_T_wc = cur.T_cw.inverse();
  if (out.keyframe && cur.reference_kf) {
    out.keyframe_id = cur.reference_kf->id();
    out.new_keyframe = cur.reference_kf;
  }
  out.on_mover = cur.on_mover;
  if (mover_track_.active(cur.id))
    out.mover = TrackOutcome::MoverRegion{mover_track_.region(), mover_track_.near_depth(), mover_track_.far_depth(),
                                          mover_track_.config().depth_margin};
  const std::optional<Relocalization> relocalized = std::exchange(relocalized_, std::nullopt);
  if (state_ == TrackState::Ok && !out.new_segment) out.relocalized = relocalized;  // not when local-map tracking failed
  if (out.relocalized) ++relocalizations_;  // a fix its local-map check refused is not one
  last_ = cur;
  last_is_keyframe_ = out.keyframe;
  out.timings.track_ms = ms_since(t_start);
  return out;
}

void Tracker::record_fates(const Frame& cur, TrackOutcome& out) {
  for (std::size_t i = 0; i < cur.map_points.size(); ++i)
    if (cur.map_points[i]) out.keypoint_fate[i] = cur.outlier[i] ? KeypointFate::Outlier : KeypointFate::Inlier;
}

// Temporary depth points are gone (clean_temporary_matches), so every match left is a map point.
PoseResiduals Tracker::inlier_residuals(const Frame& cur, const PinholeCamera& camera) {
  PoseResiduals r;
  const FrameFeatures& F = *cur.features;
  for (std::size_t i = 0; i < cur.map_points.size(); ++i) {
    if (!cur.map_points[i] || cur.outlier[i]) continue;
    const Eigen::Vector3d p_c = cur.T_cw * cur.map_points[i]->position();
    if (p_c.z() <= 0) continue;
    const Eigen::Vector2d uv(F.keypoints[i].pt.x, F.keypoints[i].pt.y);
    r.reprojection_px.push_back(static_cast<float>((camera.project(p_c) - uv).norm()));
    if (!F.has_depth(i)) continue;
    r.depth_m.push_back(static_cast<float>(std::abs(p_c.z() - F.depth[i])));
    r.measured_depth_m.push_back(F.depth[i]);
  }
  return r;
}

void Tracker::start_in_loaded_map(long next_frame_id, int segments) {
  next_frame_id_ = std::max(next_frame_id_, next_frame_id);
  segments_ = segments;
  state_ = TrackState::Lost;
  awaiting_loaded_map_ = true;
}

bool Tracker::initialize(Frame& cur, const Eigen::Isometry3d& T_cw) {
  if (static_cast<int>(cur.features->size()) < kMinKeypointsToInitialize) return false;
  int with_depth = 0;
  for (std::size_t i = 0; i < cur.features->size(); ++i) with_depth += cur.features->has_depth(i);
  if (with_depth < kMinKeypointsToInitialize / 2) return false;
  cur.T_cw = T_cw;
  cur.has_pose = true;
  std::fill(cur.map_points.begin(), cur.map_points.end(), nullptr);
  ++segments_;
  insert_keyframe_with_depth_points(cur, true);
  last_is_keyframe_ = true;
  spdlog::debug("map segment {} initialised with {} points", segments_, cur.num_tracked());
  return true;
}

void Tracker::refresh_last_frame(long frame_id) {
  // The reference keyframe may have moved (Local BA): re-anchor the last pose to it. A keyframe frame keeps
  // its own pose unless a loop correction moved the map (re-anchoring it after every Local BA measured worse:
  // BENCHMARKS.md, "Why the defaults are what they are").
  const long corrections = map_.corrections();
  const bool map_corrected = corrections != seen_corrections_;
  seen_corrections_ = corrections;
  if (last_.reference_kf && (!last_is_keyframe_ || map_corrected))
    last_.T_cw = last_T_c_ref_ * last_.reference_kf->pose();
  if (last_is_keyframe_ || state_ != TrackState::Ok) return;
  // RGB-D visual odometry: temporary points from the last frame's depth give the motion model more matches.
  const FrameFeatures& L = *last_.features;
  std::vector<std::pair<float, int>> by_depth;
  for (std::size_t i = 0; i < L.size(); ++i)
    if (L.has_depth(i)) by_depth.emplace_back(L.depth[i], static_cast<int>(i));
  std::sort(by_depth.begin(), by_depth.end());
  const Eigen::Isometry3d T_wc = last_.T_cw.inverse();
  int n = 0;
  for (const auto& [d, i] : by_depth) {
    const MapPointPtr& mp = last_.map_points[i];
    // Depth points on a followed mover are made too: matched in this frame they are suspects, solved last, and
    // those that miss the pose are the evidence that the mover still moves.
    if (last_.on_mover[i] && !mover_track_.active(frame_id)) continue;
    if (!mp || mp->num_observations() < 1) {
      auto tmp = std::make_shared<MapPoint>(-1, T_wc * L.unproject(i), nullptr);
      tmp->set_descriptor(L.descriptors.row(i));
      last_.map_points[i] = tmp;
      last_.outlier[i] = false;
    }
    ++n;
    if (d > close_depth_ && n > cfg_.tracking.vo_points) break;
  }
}

optim::PoseOptimConfig Tracker::pose_config() const {
  optim::PoseOptimConfig pc;
  pc.kernel = cfg_.tracking.kernel;
  // The dedicated 6-DoF solver gives the same pose as Ceres (tested against it) at 1.5-2x less cost.
  pc.solver = optim::PoseSolver::Dedicated;
  pc.observer = cfg_.tracking.pose_observer;
  return pc;
}

int Tracker::optimize_and_discard(Frame& cur, FrameTimings& t) {
  const auto t0 = Clock::now();
  const FramePoseProblem p = frame_pose_problem(cur);
  const std::vector<int>& idx = p.keypoints;
  if (idx.size() < 3) return 0;
  // Trust the established points first: when enough matches go to points already tracked as inliers in several
  // frames, the first round solves on those alone and the others (temporary depth points, young map points) join
  // only where they agree with that pose. A mover entering the view brings many young points that agree with
  // each other (its own motion); solved on all at once, they can outvote the map.
  const std::vector<bool> suspect = mover_suspects(cur, p);
  std::vector<bool> young(idx.size(), false);
  int established = 0;
  for (std::size_t k = 0; k < idx.size(); ++k) {
    young[k] = !cur.map_points[idx[k]]->is_established(cur.id, cfg_.tracking.established_found,
                                                        cfg_.tracking.established_age);
    established += !young[k] && (suspect.empty() || !suspect[k]);
  }
  const bool trust_established = cfg_.tracking.established_found > 0 && established >= kMinEstablished;

  const optim::PoseOptimConfig pc = pose_config();
  auto res = suspect.empty() ? optim::optimize_pose(camera_, cur.T_cw, p.points, p.observations, pc,
                                                    trust_established ? &young : nullptr)
                             : solve_without_suspects(cur, p, pc, suspect, trust_established ? &young : nullptr);
  if (!suspect.empty()) follow_mover(cur, p, suspect, res);
  if (cfg_.tracking.near_mover_check) drop_near_mover(cur, p, pc, trust_established ? &young : nullptr, res);
  cur.has_pose = true;
  int inliers = 0;
  for (std::size_t k = 0; k < idx.size(); ++k) {
    cur.outlier[idx[k]] = res.outlier[k];
    if (!res.outlier[k] && cur.map_points[idx[k]]->num_observations() > 0) ++inliers;
  }
  t.pose_ms += ms_since(t0);
  return inliers;
}

void Tracker::drop_near_mover(Frame& cur, const FramePoseProblem& p, const optim::PoseOptimConfig& pc,
                              const std::vector<bool>* young, optim::PoseOptimResult& res) {
  const NearMoverVerdict v = check_near_mover(camera_, cur.T_cw, p.points, p.observations, pc, cfg_.tracking.near_mover);
  if (!v.moving) {
    if (!v.split)
      spdlog::trace("frame {}: no near-mover test ({} near at {:.2f} m, {} far at {:.2f} m, {} far inliers)", cur.id,
                    v.near, v.near_depth, v.far, v.far_depth, v.far_inliers);
    else
      spdlog::trace("frame {}: near cluster kept ({} of {} near at {:.2f} m off, median chi2 {:.1f} gates; {} far at "
                    "{:.2f} m)",
                    cur.id, v.moving_points, v.near, v.near_depth, v.near_median_chi2, v.far, v.far_depth);
    return;
  }
  // Solve again on everything but the mover, from the far cluster's pose.
  Eigen::Isometry3d T = v.T_far;
  const optim::PoseOptimResult kept_res = solve_leaving_out(T, p, pc, v.mover, young);
  cur.T_cw = T;
  res.outlier = kept_res.outlier;
  res.inliers = kept_res.inliers;
  ++near_mover_frames_;
  spdlog::debug("frame {}: near mover ({} of {} near matches at {:.2f} m move against {} far at {:.2f} m; near "
                "median chi2 {:.1f} gates)",
                cur.id, v.moving_points, v.near, v.near_depth, v.far, v.far_depth, v.near_median_chi2);
  const FrameFeatures& F = *cur.features;
  std::vector<int> near_keypoints;
  std::vector<float> depths;
  for (std::size_t k = 0; k < p.points.size(); ++k) {
    if (!v.mover[k]) continue;
    const int i = p.keypoints[k];
    cur.on_mover[i] = true;
    const MapPointPtr& mp = cur.map_points[i];
    if (mp->num_observations() > 0) mp->mark_moving();
    // The mover's extent from the keypoints whose own depth is near too: a near point matched to a keypoint of the
    // room would stretch the depth band over the room.
    if (!F.has_depth(i) || F.depth[i] >= v.split_depth) continue;
    near_keypoints.push_back(i);
    depths.push_back(F.depth[i]);
  }
  if (depths.empty()) return;
  // Unmatched keypoints on the mover too: inside its image region and depth band (with a margin), as the person
  // filter does with a detector's box.
  const auto [near, far] = mover_depth_band(depths);
  mover_track_.confirm(cur.id, Eigen::AlignedBox2f(), near, far);
  Eigen::AlignedBox2f region;
  for (int i : near_keypoints)
    if (mover_track_.in_band(F.depth[i])) region.extend(Eigen::Vector2f(F.keypoints[i].pt.x, F.keypoints[i].pt.y));
  mover_track_.confirm(cur.id, region, near, far);
  mark_mover_keypoints(cur);
}

optim::PoseOptimResult Tracker::solve_leaving_out(Eigen::Isometry3d& T_cw, const FramePoseProblem& p,
                                                 const optim::PoseOptimConfig& pc, const std::vector<bool>& left_out,
                                                 const std::vector<bool>* young) const {
  std::vector<Eigen::Vector3d> points;
  std::vector<optim::Observation> obs;
  std::vector<bool> kept_young;
  std::vector<std::size_t> kept;
  for (std::size_t k = 0; k < left_out.size(); ++k) {
    if (left_out[k]) continue;
    kept.push_back(k);
    points.push_back(p.points[k]);
    obs.push_back(p.observations[k]);
    if (young) kept_young.push_back((*young)[k]);
  }
  optim::PoseOptimResult res = optim::optimize_pose(camera_, T_cw, points, obs, pc, young ? &kept_young : nullptr);
  std::vector<bool> outlier(left_out.size(), true);
  for (std::size_t j = 0; j < kept.size(); ++j) outlier[kept[j]] = res.outlier[j];
  res.outlier = std::move(outlier);
  return res;
}

optim::PoseOptimResult Tracker::solve_without_suspects(Frame& cur, const FramePoseProblem& p,
                                                      const optim::PoseOptimConfig& pc, const std::vector<bool>& suspect,
                                                      const std::vector<bool>* young) const {
  // The suspects never pull: a carried box moves almost with the camera, so its points miss the room's pose by a
  // few pixels only, and once let back in at the plain gate they drag the pose a little every frame.
  optim::PoseOptimResult res = solve_leaving_out(cur.T_cw, p, pc, suspect, young);
  // A suspect that fits the room's pose is kept as a match (a box held still), without having pulled.
  for (std::size_t k = 0; k < suspect.size(); ++k) {
    if (!suspect[k]) continue;
    const Eigen::Vector3d p_c = cur.T_cw * p.points[k];
    int dof = 0;
    res.outlier[k] =
        p_c.z() <= 0 || optim::whitened_chi2(camera_, p.observations[k], p_c, dof) > optim::chi2_threshold(dof);
    res.inliers += !res.outlier[k];
  }
  return res;
}

std::vector<bool> Tracker::mover_suspects(const Frame& cur, const FramePoseProblem& p) const {
  if (!mover_track_.active(cur.id)) return {};
  const FrameFeatures& F = *cur.features;
  std::vector<bool> suspect(p.keypoints.size(), false);
  int n = 0;
  for (std::size_t k = 0; k < p.keypoints.size(); ++k) {
    const int i = p.keypoints[k];
    suspect[k] = F.has_depth(i) && mover_track_.suspect({F.keypoints[i].pt.x, F.keypoints[i].pt.y}, F.depth[i]);
    n += suspect[k];
  }
  if (n == 0) return {};
  return suspect;
}

void Tracker::follow_mover(Frame& cur, const FramePoseProblem& p, const std::vector<bool>& suspect,
                           const optim::PoseOptimResult& res) {
  const FrameFeatures& F = *cur.features;
  std::vector<float> depths;
  int suspects = 0;
  for (std::size_t k = 0; k < suspect.size(); ++k) {
    if (!suspect[k]) continue;
    ++suspects;
    if (res.outlier[k]) depths.push_back(F.depth[p.keypoints[k]]);
  }
  const int missing = static_cast<int>(depths.size());
  const bool moves = missing >= mover_track_.config().min_confirming &&
                     missing >= cfg_.tracking.near_mover.min_moving_share * suspects;
  if (moves) {
    // Its region: every keypoint at the mover's depth where it may be now, matched or not (the matches of one
    // solve, against a keyframe say, cover part of it only; a region shrunk to them lets the rest into the map).
    const auto [near, far] = mover_depth_band(depths);
    MoverTrack searched = mover_track_;
    searched.confirm(cur.id, mover_track_.region(), near, far);
    Eigen::AlignedBox2f region;
    for (std::size_t i = 0; i < F.size(); ++i)
      if (F.has_depth(i) && searched.suspect({F.keypoints[i].pt.x, F.keypoints[i].pt.y}, F.depth[i]))
        region.extend(Eigen::Vector2f(F.keypoints[i].pt.x, F.keypoints[i].pt.y));
    mover_track_.confirm(cur.id, region, near, far);
    for (std::size_t k = 0; k < suspect.size(); ++k) {
      if (!suspect[k] || !res.outlier[k]) continue;
      const MapPointPtr& mp = cur.map_points[p.keypoints[k]];
      if (mp->num_observations() > 0) mp->mark_moving();
    }
  }
  spdlog::debug("frame {}: followed mover: {} of {} suspects miss the pose{} (region {:.0f},{:.0f}-{:.0f},{:.0f}, "
                "{:.2f}-{:.2f} m)",
                cur.id, missing, suspects, moves ? " (still moving)" : "", mover_track_.region().min().x(),
                mover_track_.region().min().y(), mover_track_.region().max().x(), mover_track_.region().max().y(),
                mover_track_.near_depth(), mover_track_.far_depth());
  mark_mover_keypoints(cur);
}

void Tracker::mark_mover_keypoints(Frame& cur) const {
  const FrameFeatures& F = *cur.features;
  for (std::size_t i = 0; i < F.size(); ++i)
    if (F.has_depth(i) && mover_track_.on_mover({F.keypoints[i].pt.x, F.keypoints[i].pt.y}, F.depth[i]))
      cur.on_mover[i] = true;
}

bool Tracker::track_initial_pose(Frame& cur, FrameTimings& t) {
  if (!has_velocity_) return track_reference_keyframe(cur, reference_kf_, t) >= kMinInliersMotion;
  int matches = 0;
  const int inliers = track_motion_model(cur, t, &matches);
  // Most motion-model matches rejected: the constant-velocity guess was off (a jerk of the hand-held camera) and
  // the few surviving "inliers" may agree on a wrong pose. Try the reference keyframe from the last pose and keep
  // whichever explains more matches.
  const bool doubtful = inliers < kMinInliersMotion || inliers < cfg_.tracking.motion_inlier_ratio * matches;
  if (!doubtful) return true;
  Frame by_motion = cur;
  const int by_keyframe = track_reference_keyframe(cur, reference_kf_, t);
  // Compare on established points where they exist: a keyframe just made while a large mover came into view
  // holds the mover's points, and matching it would lock the pose onto the mover (synthetic obstructing box).
  const int min_found = cfg_.tracking.established_found;
  const bool judge_established = min_found > 0 && by_motion.num_established(min_found) >= kMinEstablished;
  const bool keyframe_wins = judge_established
                                 ? cur.num_established(min_found) >= by_motion.num_established(min_found)
                                 : by_keyframe >= inliers;
  if (by_keyframe >= kMinInliersMotion && keyframe_wins) {
    spdlog::debug("frame {}: motion model doubtful ({} of {} matches), reference keyframe gives {} inliers", cur.id,
                  inliers, matches, by_keyframe);
    return true;
  }
  cur = std::move(by_motion);
  return inliers >= kMinInliersMotion;
}

int Tracker::track_motion_model(Frame& cur, FrameTimings& t, int* matches) {
  auto t0 = Clock::now();
  cur.T_cw = velocity_ * last_.T_cw;
  std::fill(cur.map_points.begin(), cur.map_points.end(), nullptr);
  int n = match_last_frame(cur, last_, cfg_.tracking.motion_radius);
  if (n < cfg_.tracking.min_matches) {
    std::fill(cur.map_points.begin(), cur.map_points.end(), nullptr);
    n = match_last_frame(cur, last_, 2 * cfg_.tracking.motion_radius);
  }
  t.match_ms += ms_since(t0);
  *matches = n;
  if (n < cfg_.tracking.min_matches) return 0;
  optimize_and_discard(cur, t);
  int inliers = 0;
  for (std::size_t i = 0; i < cur.map_points.size(); ++i) {
    if (!cur.map_points[i]) continue;
    if (cur.outlier[i]) {
      cur.map_points[i]->last_seen_frame = cur.id;
      cur.map_points[i].reset();
      cur.outlier[i] = false;
    } else {
      ++inliers;  // temporary VO points count here, as they carry real depth
    }
  }
  cur.reference_kf = reference_kf_;
  return inliers;
}

int Tracker::track_reference_keyframe(Frame& cur, const KeyFramePtr& kf, FrameTimings& t) {
  if (!kf) return 0;
  auto t0 = Clock::now();
  cur.T_cw = last_.T_cw;
  std::fill(cur.map_points.begin(), cur.map_points.end(), nullptr);
  const int n = match_keyframe_by_descriptor(cur, *kf);
  t.match_ms += ms_since(t0);
  if (n < 15) return 0;
  optimize_and_discard(cur, t);
  int inliers = 0;
  for (std::size_t i = 0; i < cur.map_points.size(); ++i) {
    if (!cur.map_points[i]) continue;
    if (cur.outlier[i]) {
      cur.map_points[i].reset();
      cur.outlier[i] = false;
    } else if (cur.map_points[i]->num_observations() > 0) {
      ++inliers;
    }
  }
  cur.reference_kf = kf;
  return inliers;
}

bool Tracker::recover(Frame& cur, FrameTimings& t) {
  // Try the keyframes around the last reference, best first, from the motion-model prediction.
  if (!reference_kf_) return relocalize(cur, t);  // a loaded map: no reference yet
  std::vector<KeyFramePtr> candidates{reference_kf_};
  for (const auto& kf : reference_kf_->best_covisibles(5)) candidates.push_back(kf);
  const Eigen::Isometry3d predicted = (has_velocity_ ? velocity_ : Eigen::Isometry3d::Identity()) * last_.T_cw;
  for (const auto& kf : candidates) {
    if (kf->is_bad()) continue;
    last_.T_cw = predicted;
    // After a loss a pose from few inliers is often a wrong one: ask as much as relocalization does.
    if (track_reference_keyframe(cur, kf, t) >= cfg_.relocalization.min_inliers) {
      last_recovery_frame_id_ = cur.id;
      fix_in_foreign_map_ = in_foreign_map();
      reference_kf_ = kf;
      spdlog::info("tracking recovered at t={:.3f} against keyframe {}", cur.timestamp, kf->id());
      return true;
    }
  }
  return relocalize(cur, t);
}

void Tracker::chain_lost_frame(const Frame& cur, FrameTimings& t) {
  chain_step_ = {};
  const RelocalizationConfig& rc = cfg_.relocalization;
  if (!in_foreign_map() || (rc.lost_views == 0 && !rc.place_back_lost_frames)) return;
  // Every lost frame, whichever way it is found: the frames before it are then placed back from it.
  const auto t0 = Clock::now();
  chain_step_ = lost_chain_.add(records_.size(), cur.features);
  t.match_ms += ms_since(t0);
}

bool Tracker::relocalize(Frame& cur, FrameTimings& t) {
  const RelocalizationConfig& rc = cfg_.relocalization;
  if (pose_hint_) {
    const auto t0 = Clock::now();
    const bool found = relocalize_near_hint(cur);
    t.match_ms += ms_since(t0);
    if (found) return true;
  }
  if (!places_ || !cfg_.relocalization.enabled) return false;
  const auto t0 = Clock::now();
  // In a map this session did not build (a loaded map, or localization only) the frame is often between mapped
  // viewpoints, far from any one keyframe: more candidates, fewer inliers asked, and a candidate's covisible
  // neighbourhood tried as a whole. The local-map check that follows verifies.
  const bool foreign = in_foreign_map();
  const auto candidates = places_->query(places_->signature(*cur.features),
                                         foreign ? rc.loaded_map_min_score : rc.min_score,
                                         foreign ? rc.loaded_map_candidates : rc.candidates);
  LocalizationConfig lc;
  lc.min_inliers = foreign ? rc.loaded_map_min_inliers : rc.min_inliers;
  lc.kernel = cfg_.tracking.kernel;
  LocalizationConfig wide = lc;
  wide.ransac_iterations = kNeighbourhoodRansacIterations;
  std::unordered_set<long> tried;  // keyframes whose points were already matched in a neighbourhood
  for (const auto& cand : candidates) {
    if (tried.contains(cand.keyframe->id())) continue;
    int inliers = locate_against_keyframe(cur, *cand.keyframe, lc);
    if (inliers == 0 && foreign) inliers = locate_in_neighbourhood(cur, *cand.keyframe, wide, tried);
    if (inliers == 0) continue;
    t.match_ms += ms_since(t0);
    accept_relocalization(cur, cand.keyframe, inliers, cand.score);
    spdlog::info("relocalized at t={:.3f} against keyframe {} ({} inliers, place score {})", cur.timestamp,
                 cand.keyframe->id(), inliers, cand.score);
    return true;
  }
  LocalizationConfig views_lc = wide;
  views_lc.ransac_iterations = kLostViewsRansacIterations;
  const bool found = foreign && chain_step_.new_view && lost_chain_.views() > 1 &&
                     locate_lost_views(cur, candidates, views_lc);
  t.match_ms += ms_since(t0);
  return found;
}

bool Tracker::locate_lost_views(Frame& cur, const std::vector<PlaceCandidate>& candidates,
                                const LocalizationConfig& lc) {
  if (candidates.empty()) return false;
  // The candidates' neighbourhoods as one set of points, each point once.
  std::vector<MapPointPtr> points;
  std::unordered_set<long> tried;
  std::unordered_set<const MapPoint*> seen;
  for (const auto& cand : candidates) {
    if (points.size() >= kLostViewsMaxMapPoints) break;  // the best candidates' points; the matching is brute force
    if (tried.contains(cand.keyframe->id())) continue;
    const KeyframeNeighbourhood near = keyframe_neighbourhood(*cand.keyframe, cfg_.relocalization.neighbourhood_keyframes);
    tried.insert(near.keyframe_ids.begin(), near.keyframe_ids.end());
    for (const auto& mp : near.points)
      if (seen.insert(mp.get()).second) points.push_back(mp);
  }
  const std::optional<Eigen::Isometry3d> T_cw =
      locate_points_by_depth(lost_chain_.view_points(), points, static_cast<std::uint64_t>(cur.id) + 1, lc);
  if (!T_cw) return false;
  // The views agree on a pose for this frame: its own matches at that pose, by projection, decide.
  const Eigen::Isometry3d prior = cur.T_cw;
  cur.T_cw = *T_cw;
  std::fill(cur.map_points.begin(), cur.map_points.end(), nullptr);
  std::fill(cur.outlier.begin(), cur.outlier.end(), false);
  match_local_map(cur, points, 2.0, LocalMapUse::Verification);
  const int inliers = refine_pose_on_matches(cur, lc.kernel);
  if (inliers < lc.min_inliers) {
    std::fill(cur.map_points.begin(), cur.map_points.end(), nullptr);
    cur.T_cw = prior;
    return false;
  }
  accept_relocalization(cur, candidates.front().keyframe, inliers, candidates.front().score);
  spdlog::info("relocalized at t={:.3f} from {} views chained while lost ({} inliers)", cur.timestamp,
               lost_chain_.views(), inliers);
  return true;
}

void Tracker::place_back_chained_frames(const Frame& cur) {
  const std::vector<LostFrameChain::Placement> placements = lost_chain_.placements();
  if (placements.empty() || placements.back().record != records_.size()) return;  // the chain must end at this frame
  for (const LostFrameChain::Placement& p : placements) {
    if (p.record >= records_.size() || records_[p.record].tracked) continue;
    FrameRecord& r = records_[p.record];
    r.live_T_cw = p.T_c_newest * cur.T_cw;
    r.reference = cur.reference_kf;
    r.T_c_ref = r.reference ? r.live_T_cw * r.reference->pose_inverse() : r.live_T_cw;
    r.tracked = true;
    r.placed_back = true;
    ++placed_back_;
  }
}

int Tracker::locate_in_neighbourhood(Frame& cur, const KeyFrame& kf, const LocalizationConfig& lc,
                                     std::unordered_set<long>& tried) const {
  const KeyframeNeighbourhood near = keyframe_neighbourhood(kf, cfg_.relocalization.neighbourhood_keyframes);
  tried.insert(near.keyframe_ids.begin(), near.keyframe_ids.end());
  return locate_against_points(cur, near.points, static_cast<std::uint64_t>(kf.id()) + 1, lc);
}

void Tracker::accept_relocalization(Frame& cur, const KeyFramePtr& kf, int inliers, int score) {
  last_recovery_frame_id_ = cur.id;
  fix_in_foreign_map_ = in_foreign_map();
  reference_kf_ = kf;
  cur.reference_kf = kf;
  relocalized_ = Relocalization{kf->id(), inliers, score};
}

bool Tracker::relocalize_near_hint(Frame& cur) {
  const Eigen::Vector3d centre = pose_hint_->T_wc.translation();
  const double radius = pose_hint_->radius_m;
  std::vector<std::pair<double, KeyFramePtr>> near;  // by distance, then id (keyframes() is ordered by id)
  for (const auto& kf : map_.keyframes()) {
    const double distance = (kf->camera_center() - centre).norm();
    if (!kf->is_bad() && distance <= radius) near.emplace_back(distance, kf);
  }
  std::stable_sort(near.begin(), near.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  LocalizationConfig lc;
  lc.min_inliers = cfg_.relocalization.loaded_map_min_inliers;
  lc.kernel = cfg_.tracking.kernel;
  lc.ransac_iterations = kNeighbourhoodRansacIterations;
  std::unordered_set<long> tried;
  const Eigen::Isometry3d prior = cur.T_cw;
  for (const auto& [distance, kf] : near) {
    if (tried.contains(kf->id())) continue;
    const int inliers = locate_in_neighbourhood(cur, *kf, lc, tried);
    if (inliers == 0) continue;
    if ((cur.T_cw.inverse().translation() - centre).norm() > radius) {  // a fix elsewhere: not where we were told
      std::fill(cur.map_points.begin(), cur.map_points.end(), nullptr);
      std::fill(cur.outlier.begin(), cur.outlier.end(), false);
      cur.T_cw = prior;
      continue;
    }
    accept_relocalization(cur, kf, inliers, 0);
    spdlog::info("relocalized at t={:.3f} near the given pose, against keyframe {} ({} inliers)", cur.timestamp,
                 kf->id(), inliers);
    return true;
  }
  return false;
}

void Tracker::update_local_map(Frame& cur) {
  // Keyframes that see the current matches, weighted by how many they see.
  std::map<KeyFramePtr, int, IdLess> counter;
  for (std::size_t i = 0; i < cur.map_points.size(); ++i) {
    const MapPointPtr& mp = cur.map_points[i];
    if (!mp || mp->is_bad()) continue;
    for (const auto& [kf, idx] : mp->observations()) counter[kf]++;
  }
  local_keyframes_.clear();
  KeyFramePtr best;
  int best_count = 0;
  for (const auto& [kf, c] : counter) {
    if (kf->is_bad()) continue;
    if (c > best_count) {
      best_count = c;
      best = kf;
    }
    local_keyframes_.push_back(kf);
    kf->local_for_frame = cur.id;
  }
  // Add neighbours: best covisibles, children and parent of each, up to the budget.
  const std::size_t direct = local_keyframes_.size();
  for (std::size_t k = 0; k < direct && local_keyframes_.size() < static_cast<std::size_t>(cfg_.tracking.max_local_keyframes); ++k) {
    const KeyFramePtr kf = local_keyframes_[k];
    auto add = [&](const KeyFramePtr& n) {
      if (n && !n->is_bad() && n->local_for_frame != cur.id) {
        n->local_for_frame = cur.id;
        local_keyframes_.push_back(n);
        return true;
      }
      return false;
    };
    for (const auto& n : kf->best_covisibles(10))
      if (add(n)) break;
    for (const auto& c : kf->children())
      if (add(c)) break;
    add(kf->parent());
  }
  if (best) {
    reference_kf_ = best;
    cur.reference_kf = best;
  }
  local_points_.clear();
  for (const auto& kf : local_keyframes_)
    for (const auto& mp : kf->map_points()) {
      if (!mp || mp->is_bad() || mp->track_reference_frame == cur.id) continue;
      mp->track_reference_frame = cur.id;
      local_points_.push_back(mp);
    }
}

bool Tracker::track_local_map(Frame& cur, FrameTimings& t) {
  auto t0 = Clock::now();
  update_local_map(cur);
  for (std::size_t i = 0; i < cur.map_points.size(); ++i) {
    const MapPointPtr& mp = cur.map_points[i];
    if (!mp) continue;
    mp->last_seen_frame = cur.id;
    mp->increase_visible();
  }
  const bool recently_recovered = cur.id < last_recovery_frame_id_ + 2;
  match_local_map(cur, local_points_, recently_recovered ? 2.0 : 1.0);
  t.match_ms += ms_since(t0);
  optimize_and_discard(cur, t);
  int inliers = 0, odometry_inliers = 0;
  for (std::size_t i = 0; i < cur.map_points.size(); ++i) {
    const MapPointPtr& mp = cur.map_points[i];
    if (!mp) continue;
    if (cur.outlier[i]) {
      mp->increase_flagged();
      continue;
    }
    mp->increase_found();
    if (mp->num_observations() > 0) ++inliers;
    else ++odometry_inliers;
  }
  // In a map this session did not build the fix is checked on its own frame: the next one, tracked from it, sees as
  // little of the map (a fix between mapped viewpoints had 40 inliers, its next frame 33-39) and goes on by odometry.
  const bool checks_fix = fix_in_foreign_map_ ? cur.id == last_recovery_frame_id_ : recently_recovered;
  if (checks_fix)
    return inliers >= (fix_in_foreign_map_ ? cfg_.relocalization.loaded_map_check_inliers : cfg_.relocalization.check_inliers);
  // Localization only: where the map thins out (a view it was not built from), the last frame's depth points carry
  // the pose as visual odometry until the map is in view again.
  if (localization_only_) return inliers + odometry_inliers >= cfg_.tracking.min_inliers_local_map;
  return inliers >= cfg_.tracking.min_inliers_local_map;
}

void Tracker::clean_temporary_matches(Frame& cur) {
  for (auto& mp : cur.map_points)
    if (mp && mp->num_observations() < 1 && mp->id() < 0) mp.reset();
}

bool Tracker::need_keyframe(const Frame& cur, int inliers) const {
  if (localization_only_) return false;
  if (!reference_kf_) return true;
  const std::size_t n_kfs = map_.num_keyframes();
  // The reference keyframe's points that count: seen by 3 keyframes (2 while the map is that small).
  const int min_obs = n_kfs <= 2 ? 2 : 3;
  const int ref_matches = reference_kf_->tracked_map_points(min_obs);
  const bool mapping_idle = sink_.accepts_keyframes();
  const FrameFeatures& F = *cur.features;
  int tracked_close = 0, untracked_close = 0;
  for (std::size_t i = 0; i < F.size(); ++i) {
    if (!F.is_close(i)) continue;
    if (cur.map_points[i] && !cur.outlier[i]) ++tracked_close;
    else ++untracked_close;
  }
  // Many close points seen but few of them in the map: a keyframe adds cheap, well-constrained structure.
  // ORB-SLAM3 would take one at every such frame; with a person close to the camera that is every frame (its
  // keypoints are close and never tracked), flooding the map. A short gap keeps the rule for real new structure.
  const TrackingConfig& tc = cfg_.tracking;
  const bool need_close = tracked_close < tc.close_tracked_max && untracked_close > tc.close_untracked_min &&
                          cur.id >= last_kf_frame_id_ + tc.close_keyframe_gap;
  // While the map has one keyframe, every frame sees it well: ask for less overlap before the second.
  constexpr double kFirstKeyframesRatio = 0.4;
  const double ref_ratio = n_kfs < 2 ? kFirstKeyframesRatio : tc.keyframe_inlier_ratio;
  const long max_frames = std::max<long>(1, std::lround(cfg_.fps));  // at least one keyframe a second
  const bool c1a = cur.id >= last_kf_frame_id_ + max_frames;
  const bool c1b = mapping_idle;
  const bool c1c = inliers < ref_matches * tc.keyframe_urgent_ratio || need_close;
  const bool c2 = (inliers < ref_matches * ref_ratio || need_close) && inliers > tc.keyframe_min_inliers;
  spdlog::debug("frame {}: inliers {} ref_matches {} close tracked {} untracked {} -> c1a {} c1c {} c2 {}", cur.id,
                inliers, ref_matches, tracked_close, untracked_close, c1a, c1c, c2);
  if (!((c1a || c1b || c1c) && c2)) return false;
  if (mapping_idle) return true;
  sink_.interrupt_ba();
  constexpr std::size_t kMaxQueuedKeyframes = 3;  // beyond this, mapping falls behind: skip this one
  return sink_.queued() < kMaxQueuedKeyframes;
}

void Tracker::create_keyframe(Frame& cur) { insert_keyframe_with_depth_points(cur, false); }

KeyFramePtr Tracker::insert_keyframe_with_depth_points(Frame& cur, bool all_depth_points) {
  auto kf = std::make_shared<KeyFrame>(map_.next_keyframe_id(), cur);
  kf->set_segment(segments_);
  const FrameFeatures& F = *cur.features;
  std::vector<std::pair<float, int>> by_depth;
  for (std::size_t i = 0; i < F.size(); ++i)
    if (F.has_depth(i)) by_depth.emplace_back(F.depth[i], static_cast<int>(i));
  std::sort(by_depth.begin(), by_depth.end());
  const Eigen::Isometry3d T_wc = cur.T_cw.inverse();
  int n = 0;
  for (const auto& [d, i] : by_depth) {
    const MapPointPtr& existing = cur.map_points[i];
    if (cur.on_mover[i]) continue;
    if (!existing || existing->num_observations() < 1) {
      auto mp = std::make_shared<MapPoint>(map_.next_map_point_id(), T_wc * F.unproject(i), kf);
      mp->add_observation(kf, i, true);
      kf->add_map_point(mp, i);
      mp->compute_descriptor();
      mp->update_normal_and_depth(scale_->scale_factors);
      map_.add_map_point(mp);
      cur.map_points[i] = mp;
      cur.outlier[i] = false;
    }
    ++n;
    if (!all_depth_points && d > close_depth_ && n > 100) break;
  }
  map_.add_keyframe(kf);
  cur.reference_kf = kf;
  reference_kf_ = kf;
  last_kf_frame_id_ = cur.id;
  sink_.insert(kf);
  return kf;
}

void Tracker::record(const Frame& cur, bool tracked) {
  FrameRecord r;
  r.timestamp = cur.timestamp;
  r.tracked = tracked;
  r.reference = cur.reference_kf;
  r.live_T_cw = cur.T_cw;
  if (r.reference) r.T_c_ref = cur.T_cw * r.reference->pose_inverse();
  else r.T_c_ref = cur.T_cw;
  records_.push_back(r);
  if (&cur != &last_) last_T_c_ref_ = r.T_c_ref;
}

}  // namespace varslam::slam
