#pragma once
// Everything the SLAM stages need to know, read once from the settings file.
#include <optional>
#include <string>

#include "features/feature_extractor.hpp"
#include "io/depth_image.hpp"
#include "io/settings.hpp"
#include "optim/kernel.hpp"
#include "optim/local_ba.hpp"
#include "optim/pose_optimizer.hpp"

namespace varslam::slam {

struct TrackingConfig {
  optim::KernelConfig kernel;      // pose-only optimisation (ORB-SLAM3: Huber)
  double motion_radius = 15.0;     // search radius (pixels at level 0) when matching against the last frame
  int min_matches = 20;            // motion-model matches needed before optimising
  double motion_inlier_ratio = 0.5;  // fewer motion-model inliers than this share of matches: cross-check
  int established_found = 3;  // frames a point must have been an inlier in to anchor the first pose round (0: off)
  // ... and was created at least this many frames ago. A slowly moving box stays consistent with the camera for a
  // few frames, long enough to be found 3 times; after 10 frames it has moved off. Measured (synthetic benchmark,
  // 3 s sequences, kernel config): obstructing_box 34.3 -> 24.1 cm, mixed 4.2 -> 3.7, walking 6.5 -> 6.0, static
  // unchanged; full config mixed 12.2 -> 4.2 but walking 3.0 -> 4.0; kitchen 4.63 -> 5.94 deterministic, equal in
  // real time (three runs each: 4.76 / 5.73 / 5.78 against 6.16 / 5.58 / 5.67). 0 turns it off.
  int established_age = 10;
  int min_inliers_local_map = 30;  // inliers after local-map tracking for the frame to count as tracked
  int max_local_keyframes = 80;
  int lost_frames_before_reinit = 3;  // failed recoveries before a new map segment starts
  int vo_points = 100;             // temporary depth points in the last frame (RGB-D visual odometry)
  int close_keyframe_gap = 5;      // frames between keyframes triggered by untracked close points
  double depth_edge_ratio = 0.1;   // > 0: drop the depth of keypoints on depth discontinuities (see frame.hpp)
  // Depth residual in pose optimisation and BA (optim::Observation): 0 = ORB-SLAM3's virtual right coordinate,
  // which gives depth the noise of a one-pixel stereo match; > 0 = disparity bf/z alone, with sigma 1/weight
  // pixels at level 0. Kinect-class sensors measure disparity to about 1/10 pixel: ORB-SLAM3's model
  // under-weights depth, and with people filtered out of a far background a 20 cm sideways jump against a
  // 2.3 deg turn stayed unresolved. Measured (synthetic benchmark, 144 runs each; weights 0 / 4 / 10 / 20):
  // full config walking 3.95 / 0.81 / 0.64 / 0.58 cm, mixed 4.15 / 1.06 / 0.72 / 0.82, static 0.30 / 0.28 /
  // 0.27 / 0.33; real kitchen (deterministic) 5.94 / 4.94 / 4.83 / 4.84.
  double disparity_weight = 10.0;
  // Set when depth comes from a separate, unregistered camera (raw Kinect v1, 7-Scenes): the depth image is
  // warped into the colour camera before keypoint depths are read (keys depth.camera_fx/fy/cx/cy/tx/ty/tz).
  std::optional<DepthCameraRig> depth_rig;
  // Without depth_rig: check on a few frames whether depth is registered to colour, and register it when it
  // clearly is not (runner.cpp; depth.registration: auto | off).
  bool estimate_registration = true;
  optim::PoseProblemObserver pose_observer;  // debug/benchmark hook: sees every pose problem (empty: none)
};

struct MappingConfig {
  optim::KernelConfig kernel;  // Local BA (paper: adaptive Barron; ORB-SLAM3: Huber)
  int ba_outer_iterations = 3;
  int ba_iterations = 5;
  int ba_refine_iterations = 10;
  int triangulation_neighbours = 10;
  int max_ba_keyframes = 20;  // optimised keyframes per Local BA (the most covisible); others observing stay fixed
  double keyframe_redundancy = 0.9;  // share of points seen by >= 3 other keyframes that makes a keyframe redundant
  bool cull_keyframes = true;
  optim::LocalBaObserver ba_observer;  // debug/benchmark hook: sees every Local BA problem (empty: none)
};

struct LoopConfig {
  bool enabled = true;
  int min_keyframes = 10;       // keyframes in the map before loops are sought
  int min_keyframe_gap = 10;    // a candidate is at least this many keyframe ids older than the query
  int min_score = 30;           // signature matches (of 256) for a place candidate
  std::size_t candidates = 3;   // best place candidates verified per keyframe
  int min_ransac_inliers = 25;  // 3-D/3-D RANSAC inliers against the candidate keyframe
  int min_inliers = 80;         // pose inliers after guided matching against the candidate's neighbourhood
  int keyframes_after_loop = 5; // keyframes skipped after a closure (the same loop is found again at once)
  // A candidate is rejected when, matched from the keyframe's own pose, its neighbourhood gives at least this share
  // of the inliers the loop pose gives (the map already agrees; the loop pose follows a mover). 0: no check.
  double max_own_pose_share = 0.2;
  int pose_graph_min_weight = 100;  // covisibility weight for a pose-graph edge (besides the spanning tree)
  bool global_ba = true;
  int global_ba_iterations = 10;
  bool final_global_ba = false;  // one global BA when the run ends
};

struct RelocalizationConfig {
  bool enabled = true;
  int min_score = 25;          // signature matches (of 256) for a candidate keyframe
  std::size_t candidates = 5;  // candidates tried per lost frame
  int min_inliers = 30;        // pose inliers against the candidate keyframe
};

struct SlamConfig {
  OrbParams orb;
  ExtractorKind extractor = ExtractorKind::Ours;
  TrackingConfig tracking;
  MappingConfig mapping;
  LoopConfig loop;
  RelocalizationConfig relocalization;
  double fps = 30.0;
};

/// Reads `tracking.*`, `mapping.*`, `features.*` (and the ORB parameters) from the settings; a bad value is a
/// ConfigError naming the file and key. Kernel names: huber, barron-fixed, barron-adaptive, none.
SlamConfig slam_config_from(const Settings& settings);
optim::KernelType parse_kernel(const std::string& name, const std::string& where);
std::string kernel_name(optim::KernelType type);

}  // namespace varslam::slam
