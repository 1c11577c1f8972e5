#include "slam/config.hpp"

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/settings_registry.hpp"

namespace varslam::slam {

optim::KernelType parse_kernel(const std::string& name, const std::string& where) {
  if (name == "huber") return optim::KernelType::Huber;
  if (name == "barron-fixed") return optim::KernelType::BarronFixed;
  if (name == "barron-adaptive") return optim::KernelType::BarronAdaptive;
  if (name == "none") return optim::KernelType::None;
  throw ConfigError(fmt::format("{}: unknown kernel '{}' (use huber, barron-fixed, barron-adaptive or none)", where, name));
}

std::string kernel_name(optim::KernelType type) {
  switch (type) {
    case optim::KernelType::Huber: return "huber";
    case optim::KernelType::BarronFixed: return "barron-fixed";
    case optim::KernelType::BarronAdaptive: return "barron-adaptive";
    case optim::KernelType::None: return "none";
  }
  return "?";
}

namespace {

// Types, ranges and choices are checked by the registry; what is left here is how values map onto the structs.
optim::KernelConfig read_kernel(const Settings& s, const std::string& section) {
  optim::KernelConfig k;
  k.type = kernel_type_named(setting<std::string>(s, section + ".kernel"));
  k.barron_alpha = setting<double>(s, section + ".barron_alpha");
  k.barron_c = setting<double>(s, section + ".barron_c");
  k.tau = setting<double>(s, section + ".tau");
  k.alpha_max = setting<double>(s, section + ".alpha_max");
  k.chi2_gates = setting<bool>(s, section + ".chi2_gates");
  k.fit = setting<std::string>(s, section + ".alpha_fit") == "norm" ? robust::AlphaFit::ResidualNorm
                                                                    : robust::AlphaFit::PerComponent;
  return k;
}

// The depth camera's intrinsics and its origin in the colour frame; absent (registered depth) without
// depth.camera_fx. Its image size is the colour camera's (both 640x480 on a Kinect).
std::optional<DepthCameraRig> read_depth_rig(const Settings& s) {
  const auto fx = setting_if_given(s, "depth.camera_fx");
  if (!fx || *fx == 0.0) return std::nullopt;
  DepthCameraRig rig;
  PinholeCamera& d = rig.depth;
  d.width = s.camera.width;
  d.height = s.camera.height;
  d.fx = *fx;
  d.fy = setting_if_given(s, "depth.camera_fy").value_or(d.fx);
  d.cx = setting_if_given(s, "depth.camera_cx").value_or(s.camera.cx);
  d.cy = setting_if_given(s, "depth.camera_cy").value_or(s.camera.cy);
  rig.t_colour_depth = {setting<double>(s, "depth.camera_tx"), setting<double>(s, "depth.camera_ty"),
                        setting<double>(s, "depth.camera_tz")};
  return rig;
}

}  // namespace

SlamConfig slam_config_from(const Settings& s) {
  SlamConfig c;
  c.fps = s.fps;
  c.orb.n_features = s.orb.n_features;
  c.orb.scale_factor = s.orb.scale_factor;
  c.orb.n_levels = s.orb.n_levels;
  c.orb.ini_th_fast = s.orb.ini_th_fast;
  c.orb.min_th_fast = s.orb.min_th_fast;
  c.orb.threads = s.orb.threads;
  c.extractor = setting<std::string>(s, "features.extractor") == "ours" ? ExtractorKind::Ours : ExtractorKind::OpenCV;

  TrackingConfig& t = c.tracking;
  t.kernel = read_kernel(s, "tracking");
  t.motion_radius = setting<double>(s, "tracking.motion_radius");
  t.min_matches = setting<int>(s, "tracking.min_matches");
  t.motion_inlier_ratio = setting<double>(s, "tracking.motion_inlier_ratio");
  t.established_found = setting<int>(s, "tracking.established_found");
  t.established_age = setting<int>(s, "tracking.established_age");
  t.near_mover_check = setting<bool>(s, "tracking.near_mover_check");
  t.near_mover.min_depth_ratio = setting<double>(s, "tracking.near_mover_depth_ratio");
  t.near_mover.min_moving_share = setting<double>(s, "tracking.near_mover_share");
  t.near_mover.min_points = setting<int>(s, "tracking.near_mover_min_points");
  t.mover_track.memory = setting<int>(s, "tracking.near_mover_memory");
  t.min_inliers_local_map = setting<int>(s, "tracking.min_inliers");
  t.max_local_keyframes = setting<int>(s, "tracking.max_local_keyframes");
  t.depth_edge_ratio = setting<double>(s, "depth.edge_ratio");
  t.rolling_shutter_s = setting<double>(s, "camera.rolling_shutter_ms") / 1000.0;
  t.depth_rig = read_depth_rig(s);
  t.estimate_registration = setting<std::string>(s, "depth.registration") == "auto";
  t.registration_max_baseline_m = setting<double>(s, "depth.registration_max_baseline_m");
  t.disparity_weight = setting<double>(s, "depth.disparity_weight");
  t.vo_points = setting<int>(s, "tracking.vo_points");
  t.close_keyframe_gap = setting<int>(s, "tracking.close_keyframe_gap");
  t.lost_frames_before_reinit = setting<int>(s, "tracking.lost_frames_before_reinit");
  t.keyframe_inlier_ratio = setting<double>(s, "tracking.keyframe_inlier_ratio");
  t.keyframe_urgent_ratio = setting<double>(s, "tracking.keyframe_urgent_ratio");
  t.keyframe_min_inliers = setting<int>(s, "tracking.keyframe_min_inliers");
  t.close_tracked_max = setting<int>(s, "tracking.close_tracked_max");
  t.close_untracked_min = setting<int>(s, "tracking.close_untracked_min");

  MappingConfig& m = c.mapping;
  m.kernel = read_kernel(s, "mapping");
  m.ba_outer_iterations = setting<int>(s, "mapping.ba_outer_iterations");
  m.ba_iterations = setting<int>(s, "mapping.ba_iterations");
  m.ba_refine_iterations = setting<int>(s, "mapping.ba_refine_iterations");
  m.ba_solver = setting<std::string>(s, "mapping.ba_solver") == "schur" ? optim::BaSolver::Schur : optim::BaSolver::Ceres;
  m.triangulation_neighbours = setting<int>(s, "mapping.triangulation_neighbours");
  m.max_ba_keyframes = setting<int>(s, "mapping.max_ba_keyframes");
  m.keyframe_redundancy = setting<double>(s, "mapping.keyframe_redundancy");
  m.min_found_ratio = setting<double>(s, "mapping.min_found_ratio");
  m.cull_keyframes = setting<bool>(s, "mapping.cull_keyframes");

  LoopConfig& l = c.loop;
  l.enabled = setting<bool>(s, "loop.enabled");
  l.min_keyframes = setting<int>(s, "loop.min_keyframes");
  l.min_keyframe_gap = setting<int>(s, "loop.min_keyframe_gap");
  l.min_score = setting<int>(s, "loop.min_score");
  l.candidates = static_cast<std::size_t>(setting<int>(s, "loop.candidates"));
  l.min_ransac_inliers = setting<int>(s, "loop.min_ransac_inliers");
  l.min_inliers = setting<int>(s, "loop.min_inliers");
  l.keyframes_after_loop = setting<int>(s, "loop.keyframes_after_loop");
  l.pose_graph_min_weight = setting<int>(s, "loop.pose_graph_min_weight");
  l.max_own_pose_share = setting<double>(s, "loop.max_own_pose_share");
  l.global_ba = setting<bool>(s, "loop.global_ba");
  l.global_ba_iterations = setting<int>(s, "loop.global_ba_iterations");
  l.final_global_ba = setting<bool>(s, "loop.final_global_ba");
  l.final_dense_refine = setting<bool>(s, "loop.final_dense_refine");

  RelocalizationConfig& r = c.relocalization;
  r.enabled = setting<bool>(s, "relocalization.enabled");
  r.min_score = setting<int>(s, "relocalization.min_score");
  r.candidates = static_cast<std::size_t>(setting<int>(s, "relocalization.candidates"));
  r.min_inliers = setting<int>(s, "relocalization.min_inliers");
  r.loaded_map_min_inliers = setting<int>(s, "relocalization.loaded_map_min_inliers");
  r.loaded_map_check_inliers = setting<int>(s, "relocalization.loaded_map_check_inliers");
  r.neighbourhood_keyframes = setting<int>(s, "relocalization.neighbourhood_keyframes");
  r.loaded_map_min_score = setting<int>(s, "relocalization.loaded_map_min_score");
  r.loaded_map_candidates = setting<int>(s, "relocalization.loaded_map_candidates");
  r.loaded_map_patience = setting<int>(s, "relocalization.loaded_map_patience");
  r.check_inliers = setting<int>(s, "relocalization.check_inliers");
  r.lost_views = setting<int>(s, "relocalization.lost_views");
  r.place_back_lost_frames = setting<bool>(s, "relocalization.place_back_lost_frames");
  return c;
}

}  // namespace varslam::slam
