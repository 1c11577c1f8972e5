#include "slam/system.hpp"

namespace varslam::slam {

namespace {
std::shared_ptr<const ScaleInfo> scale_of(const SlamConfig& cfg) {
  auto s = std::make_shared<ScaleInfo>();
  s->n_levels = cfg.orb.n_levels;
  s->scale_factor = cfg.orb.scale_factor;
  s->log_scale_factor = std::log(cfg.orb.scale_factor);
  double f = 1.0;
  for (int l = 0; l < cfg.orb.n_levels; ++l, f *= cfg.orb.scale_factor) {
    s->scale_factors.push_back(f);
    s->level_sigma2.push_back(f * f);
    s->inv_level_sigma2.push_back(1.0 / (f * f));
  }
  return s;
}
}  // namespace

System::System(const SlamConfig& cfg, const PinholeCamera& camera, double close_depth, RunMode mode)
    : cfg_(cfg), mode_(mode), mapper_(cfg.mapping, map_, scale_of(cfg), close_depth),
      tracker_(cfg, camera, close_depth, map_, mapper_) {
  if (mode_ == RunMode::RealTime) mapper_.start();
}

System::~System() {
  mapper_.stop();
  map_.clear();
}

TrackOutcome System::process(const RgbdFrame& frame) {
  TrackOutcome out = tracker_.track(frame);
  if (mode_ == RunMode::Deterministic) mapper_.process_all();
  return out;
}

void System::finish() { mapper_.stop(); }

Trajectory System::camera_trajectory(bool include_lost) const {
  Trajectory traj;
  for (const FrameRecord& r : tracker_.records()) {
    if (!r.tracked && !include_lost) continue;
    if (!r.reference && !r.tracked) continue;
    StampedPose p;
    p.timestamp = r.timestamp;
    const Eigen::Isometry3d T_cw = r.reference ? r.T_c_ref * r.reference->resolved_pose() : r.T_c_ref;
    p.T_wc = T_cw.inverse();
    traj.push_back(p);
  }
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
