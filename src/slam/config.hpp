#pragma once
// Everything the SLAM stages need to know, read once from the settings file.
#include <optional>
#include <string>
#include <string_view>

#include "features/feature_extractor.hpp"
#include "io/depth_image.hpp"
#include "core/setting_keys.hpp"
#include "io/settings.hpp"
#include "optim/kernel.hpp"
#include "optim/local_ba.hpp"
#include "optim/pose_optimizer.hpp"
#include "slam/mover_track.hpp"
#include "slam/near_mover.hpp"

namespace varslam::slam {

/// A kernel name of the registry ("huber", "barron-fixed", ...) as the optimiser's type.
constexpr optim::KernelType kernel_type_named(std::string_view name) {
  if (name == "barron-fixed") return optim::KernelType::BarronFixed;
  if (name == "barron-adaptive") return optim::KernelType::BarronAdaptive;
  if (name == "none") return optim::KernelType::None;
  return optim::KernelType::Huber;
}

/// The registry's defaults of a stage's kernel keys (`tracking` for pose-only optimisation, `mapping` for Local
/// BA); a key missing from the table does not compile (its index runs past the table).
consteval optim::KernelConfig kernel_defaults(std::string_view section) {
  const auto key = [section](std::string_view name) { return setting_keys::kKeys[setting_keys::key_index(section, name)]; };
  optim::KernelConfig k;
  k.type = kernel_type_named(key("kernel").text);
  k.barron_alpha = key("barron_alpha").number;
  k.barron_c = key("barron_c").number;
  k.tau = key("tau").number;
  k.alpha_max = key("alpha_max").number;
  k.fit = key("alpha_fit").text == "norm" ? robust::AlphaFit::ResidualNorm : robust::AlphaFit::PerComponent;
  k.chi2_gates = key("chi2_gates").number != 0.0;
  return k;
}
inline constexpr optim::KernelConfig kTrackingKernelDefaults = kernel_defaults("tracking");
inline constexpr optim::KernelConfig kMappingKernelDefaults = kernel_defaults("mapping");

// Each field's meaning, range and default are in the settings registry (core/setting_keys.hpp, docs/settings.md)
// under the key it is read from (slam_config_from); what is said here is only what the registry cannot say.
struct TrackingConfig {
  optim::KernelConfig kernel = kTrackingKernelDefaults;  // pose-only optimisation: tracking.kernel, barron_*
  double motion_radius = setting_keys::real_default("tracking.motion_radius");
  int min_matches = setting_keys::int_default("tracking.min_matches");
  double motion_inlier_ratio = setting_keys::real_default("tracking.motion_inlier_ratio");
  int established_found = setting_keys::int_default("tracking.established_found");
  int established_age = setting_keys::int_default("tracking.established_age");
  bool near_mover_check = setting_keys::bool_default("tracking.near_mover_check");
  NearMoverConfig near_mover{
      .min_depth_ratio = setting_keys::real_default("tracking.near_mover_depth_ratio"),
      .min_points = setting_keys::int_default("tracking.near_mover_min_points"),
      .min_moving_share = setting_keys::real_default("tracking.near_mover_share")};
  MoverTrackConfig mover_track{.memory = setting_keys::int_default("tracking.near_mover_memory")};
  int min_inliers_local_map = setting_keys::int_default("tracking.min_inliers");
  int max_local_keyframes = setting_keys::int_default("tracking.max_local_keyframes");
  int lost_frames_before_reinit = setting_keys::int_default("tracking.lost_frames_before_reinit");
  int vo_points = setting_keys::int_default("tracking.vo_points");
  int close_keyframe_gap = setting_keys::int_default("tracking.close_keyframe_gap");
  // The keyframe decision (Tracker::need_keyframe), ORB-SLAM's RGB-D rule with its numbers as defaults.
  double keyframe_inlier_ratio = setting_keys::real_default("tracking.keyframe_inlier_ratio");
  double keyframe_urgent_ratio = setting_keys::real_default("tracking.keyframe_urgent_ratio");
  int keyframe_min_inliers = setting_keys::int_default("tracking.keyframe_min_inliers");
  int close_tracked_max = setting_keys::int_default("tracking.close_tracked_max");
  int close_untracked_min = setting_keys::int_default("tracking.close_untracked_min");
  double depth_edge_ratio = setting_keys::real_default("depth.edge_ratio");  // see frame.hpp
  double rolling_shutter_s = setting_keys::real_default("camera.rolling_shutter_ms") / 1000.0;  // see rolling_shutter.hpp
  // Depth residual of pose optimisation and BA (optim::Observation): 0 = ORB-SLAM3's virtual right coordinate,
  // > 0 = the disparity bf/z alone with sigma 1/weight pixels at level 0.
  double disparity_weight = setting_keys::real_default("depth.disparity_weight");
  // Set when depth comes from a separate, unregistered camera (raw Kinect v1, 7-Scenes): the depth image is
  // warped into the colour camera before keypoint depths are read (keys depth.camera_fx/fy/cx/cy/tx/ty/tz).
  std::optional<DepthCameraRig> depth_rig;
  // Without depth_rig: check on a few frames whether depth is registered to colour, and register it when it
  // clearly is not (pipeline/slam.cpp; depth.registration: auto | off).
  bool estimate_registration = setting_keys::text_default("depth.registration") == "auto";
  double registration_max_baseline_m = setting_keys::real_default("depth.registration_max_baseline_m");
  optim::PoseProblemObserver pose_observer;  // debug/benchmark hook: sees every pose problem (empty: none)
};

struct MappingConfig {
  optim::KernelConfig kernel = kMappingKernelDefaults;  // Local BA: mapping.kernel, barron_*, alpha_*
  int ba_outer_iterations = setting_keys::int_default("mapping.ba_outer_iterations");
  int ba_iterations = setting_keys::int_default("mapping.ba_iterations");
  int ba_refine_iterations = setting_keys::int_default("mapping.ba_refine_iterations");
  optim::BaSolver ba_solver =
      setting_keys::text_default("mapping.ba_solver") == "schur" ? optim::BaSolver::Schur : optim::BaSolver::Ceres;
  int triangulation_neighbours = setting_keys::int_default("mapping.triangulation_neighbours");
  int max_ba_keyframes = setting_keys::int_default("mapping.max_ba_keyframes");
  double keyframe_redundancy = setting_keys::real_default("mapping.keyframe_redundancy");
  double min_found_ratio = setting_keys::real_default("mapping.min_found_ratio");
  bool cull_keyframes = setting_keys::bool_default("mapping.cull_keyframes");
  optim::LocalBaObserver ba_observer;  // debug/benchmark hook: sees every Local BA problem (empty: none)
};

struct LoopConfig {
  bool enabled = setting_keys::bool_default("loop.enabled");
  int min_keyframes = setting_keys::int_default("loop.min_keyframes");       // keyframes in the map before loops are sought
  int min_keyframe_gap = setting_keys::int_default("loop.min_keyframe_gap");    // a candidate is at least this many keyframe ids older than the query
  int min_score = setting_keys::int_default("loop.min_score");           // signature matches (of 256) for a place candidate
  std::size_t candidates = setting_keys::int_default("loop.candidates");   // best place candidates verified per keyframe
  int min_ransac_inliers = setting_keys::int_default("loop.min_ransac_inliers");  // 3-D/3-D RANSAC inliers against the candidate keyframe
  int min_inliers = setting_keys::int_default("loop.min_inliers");         // pose inliers after guided matching against the candidate's neighbourhood
  int keyframes_after_loop = setting_keys::int_default("loop.keyframes_after_loop"); // keyframes skipped after a closure (the same loop is found again at once)
  // A candidate is rejected when, matched from the keyframe's own pose, its neighbourhood gives at least this share
  // of the inliers the loop pose gives (the map already agrees; the loop pose follows a mover). 0: no check.
  double max_own_pose_share = setting_keys::real_default("loop.max_own_pose_share");
  int pose_graph_min_weight = setting_keys::int_default("loop.pose_graph_min_weight");  // covisibility weight for a pose-graph edge (besides the spanning tree)
  bool global_ba = setting_keys::bool_default("loop.global_ba");
  int global_ba_iterations = setting_keys::int_default("loop.global_ba_iterations");
  bool final_global_ba = setting_keys::bool_default("loop.final_global_ba");  // one global BA when the run ends
  bool final_dense_refine = setting_keys::bool_default("loop.final_dense_refine");  // slam/dense_refinement.hpp
};

struct RelocalizationConfig {
  bool enabled = setting_keys::bool_default("relocalization.enabled");
  int min_score = setting_keys::int_default("relocalization.min_score");          // signature matches (of 256) for a candidate keyframe
  std::size_t candidates = setting_keys::int_default("relocalization.candidates");  // candidates tried per lost frame
  int min_inliers = setting_keys::int_default("relocalization.min_inliers");        // pose inliers against the candidate keyframe
  int loaded_map_min_inliers = setting_keys::int_default("relocalization.loaded_map_min_inliers");  // first fix in a loaded map
  int loaded_map_check_inliers = setting_keys::int_default("relocalization.loaded_map_check_inliers");  // its local-map check
  int neighbourhood_keyframes = setting_keys::int_default("relocalization.neighbourhood_keyframes");
  int loaded_map_min_score = setting_keys::int_default("relocalization.loaded_map_min_score");
  int loaded_map_candidates = setting_keys::int_default("relocalization.loaded_map_candidates");
  int loaded_map_patience = setting_keys::int_default("relocalization.loaded_map_patience");
  int check_inliers = setting_keys::int_default("relocalization.check_inliers");  // own map: a recovery's local-map check
  int lost_views = setting_keys::int_default("relocalization.lost_views");
  bool place_back_lost_frames = setting_keys::bool_default("relocalization.place_back_lost_frames");
};

struct SlamConfig {
  OrbParams orb;
  ExtractorKind extractor =
      setting_keys::text_default("features.extractor") == "ours" ? ExtractorKind::Ours : ExtractorKind::OpenCV;
  TrackingConfig tracking;
  MappingConfig mapping;
  LoopConfig loop;
  RelocalizationConfig relocalization;
  double fps = setting_keys::real_default("camera.fps");
};

/// Reads `tracking.*`, `mapping.*`, `features.*` (and the ORB parameters) from the settings; a bad value is a
/// ConfigError naming the file and key. Kernel names: huber, barron-fixed, barron-adaptive, none.
SlamConfig slam_config_from(const Settings& settings);
optim::KernelType parse_kernel(const std::string& name, const std::string& where);
std::string kernel_name(optim::KernelType type);

}  // namespace varslam::slam
