#include "slam/system.hpp"

#include <chrono>

#include <spdlog/spdlog.h>

#include "slam/trajectory_guard.hpp"

namespace varslam::slam {

System::System(const SlamConfig& cfg, const PinholeCamera& camera, double close_depth, RunMode mode,
               SystemObserver* observer)
    // The tracker only stores its keyframe sink here; the mapper takes the pyramid facts from the tracker's
    // extractor, so both stages use one ScaleInfo.
    : cfg_(cfg), mode_(mode), tracker_(cfg, camera, close_depth, map_, mapper_),
      mapper_(cfg.mapping, map_, tracker_.scale(), close_depth),
      loop_(cfg.loop, cfg.tracking.kernel, map_, places_, tracker_.scale()) {
  tracker_.set_place_database(&places_);
  mapper_.set_observer(observer);
  loop_.set_observer(observer);
  mapper_.set_keyframe_done([this](const KeyFramePtr& kf) { loop_.process(kf); });
  if (mode_ == RunMode::RealTime) mapper_.start();
}

System::~System() {
  mapper_.stop();
  map_.clear();
}

void System::adopt_map(const SavedMap& saved) {
  if (map_.num_keyframes() > 0) throw std::logic_error("System::adopt_map: the map is not empty");
  restore_map(saved, map_, places_, tracker_.scale());
  int segments = 0;
  for (const auto& k : saved.keyframes) segments = std::max(segments, k.segment);
  tracker_.start_in_loaded_map(saved.next_frame_id, segments);
}

SavedMap System::snapshot(MapFingerprint fingerprint) const {
  return snapshot_map(map_, places_, std::move(fingerprint), tracker_.next_frame_id());
}

SavedMap System::snapshot_now(MapFingerprint fingerprint) {
  // Between two keyframes of local mapping (and of the loop closing it runs) the map is consistent; the copy is
  // made under the map's update lock so tracking, which may add a keyframe meanwhile, waits only for the copy.
  const bool pause = mode_ == RunMode::RealTime && mapper_.running();
  if (pause) mapper_.pause();
  struct Resume {
    LocalMapper* mapper;
    ~Resume() {
      if (mapper) mapper->resume();
    }
  } resume{pause ? &mapper_ : nullptr};
  if (const auto failure = mapper_.failure()) std::rethrow_exception(failure);
  std::unique_lock lock(map_.update_mutex());
  return snapshot(std::move(fingerprint));
}

TrackOutcome System::process(const RgbdFrame& frame) {
  // After a mapping error the map is no longer consistent: every later call reports that error.
  if (const auto failure = mapper_.failure()) std::rethrow_exception(failure);
  TrackOutcome out = tracker_.track(frame);
  if (mode_ == RunMode::Deterministic) mapper_.process_all();
  return out;
}

void System::finish() {
  mapper_.stop();
  if (const auto failure = mapper_.failure()) std::rethrow_exception(failure);
  if (cfg_.loop.final_dense_refine) {
    const auto t0 = std::chrono::steady_clock::now();
    const DenseRefinementResult r = loop_.refine_with_depth();
    spdlog::info("dense refinement: {} of {} distant keyframe pairs aligned, {} within the gates moved them by {:.1f} mm "
                 "on average ({:.0f} ms)",
                 r.aligned, r.candidates, r.edges, 1000.0 * r.mean_correction_m,
                 std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  if (cfg_.loop.final_global_ba) loop_.run_global_ba();
}

Trajectory System::camera_trajectory(bool include_lost, int* repaired) const {
  Trajectory traj;
  std::vector<Eigen::Isometry3d> live;
  for (const FrameRecord& r : tracker_.records()) {
    if (!r.tracked && !include_lost) continue;
    if (!r.reference && !r.tracked) continue;
    StampedPose p;
    p.timestamp = r.timestamp;
    const Eigen::Isometry3d T_cw = r.reference ? r.T_c_ref * r.reference->resolved_pose() : r.T_c_ref;
    p.T_wc = T_cw.inverse();
    traj.push_back(p);
    live.push_back(r.live_T_cw.inverse());
  }
  const int n = repair_isolated_poses(traj, live);
  if (repaired) *repaired = n;
  return traj;
}

Trajectory System::keyframe_trajectory() const {
  Trajectory traj;
  for (const auto& kf : map_.keyframes()) {
    if (kf->is_bad()) continue;
    traj.push_back({kf->timestamp(), kf->pose_inverse()});
  }
  return traj;
}

}  // namespace varslam::slam
