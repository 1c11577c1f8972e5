#pragma once
// The settings registry: every key varslam reads, declared once with its type, default, valid range or choices
// and meaning. The YAML reader, `--set`, the ORB-SLAM3 key mapping, `varslam settings`, docs/settings.md and the
// config structs' defaults all come from this table. Pure data (no YAML), so every module can take its defaults
// from here at compile time: `int gap = setting_keys::int_default("tracking.close_keyframe_gap");` fails to
// compile when the key is not declared.
#include <iterator>
#include <limits>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace varslam::setting_keys {

enum class KeyType {
  Int,       // an integer in [lo, hi]
  Real,      // a finite number in [lo, hi] (or open at an end)
  Bool,      // true / false (ORB-SLAM files: 0 / 1)
  Choice,    // one of `choices`
  Text,      // free text
  Path,      // a file or folder; relative to the settings file when that makes it exist
  TextList,  // a YAML list of strings (default: comma separated)
  TextMap,   // a YAML map of string to string (default: "from:to,from:to")
};

struct KeySpec {
  std::string_view name;  // section.key
  KeyType type = KeyType::Real;
  double number = 0;        // default of Int / Real / Bool (0 or 1)
  std::string_view text{};  // default of Choice / Text / Path / TextList / TextMap
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;  // the range excludes that end
  std::string_view choices{};             // Choice: "a|b|c"
  std::string_view meaning{};
  std::string_view aliases{};   // other spellings read from files (ORB-SLAM3 / ORB-SLAM2 layouts), '|' separated
  bool has_default = true;      // false: absent unless given (its meaning says what then)
};

namespace detail {
inline constexpr double kInf = std::numeric_limits<double>::infinity();

constexpr KeySpec integer(std::string_view name, int def, double lo, double hi, std::string_view meaning,
                          std::string_view aliases = {}) {
  return {name, KeyType::Int, static_cast<double>(def), {}, lo, hi, false, false, {}, meaning, aliases, true};
}
// A real in [lo, hi]; `open` = "(" / ")" / "()" makes that end exclusive.
constexpr KeySpec real(std::string_view name, double def, double lo, double hi, std::string_view meaning,
                       std::string_view aliases = {}, std::string_view open = {}) {
  const bool lo_open = open.find('(') != std::string_view::npos, hi_open = open.find(')') != std::string_view::npos;
  return {name, KeyType::Real, def, {}, lo, hi, lo_open, hi_open, {}, meaning, aliases, true};
}
constexpr KeySpec positive(std::string_view name, double def, double hi, std::string_view meaning,
                           std::string_view aliases = {}) {
  return real(name, def, 0.0, hi, meaning, aliases, "(");
}
constexpr KeySpec optional_real(std::string_view name, double lo, double hi, std::string_view meaning,
                                std::string_view open = {}, std::string_view aliases = {}) {
  KeySpec k = real(name, 0.0, lo, hi, meaning, aliases, open);
  k.has_default = false;
  return k;
}
constexpr KeySpec flag(std::string_view name, bool def, std::string_view meaning) {
  return {name, KeyType::Bool, def ? 1.0 : 0.0, {}, 0, 1, false, false, {}, meaning, {}, true};
}
constexpr KeySpec choice(std::string_view name, std::string_view def, std::string_view choices,
                         std::string_view meaning) {
  return {name, KeyType::Choice, 0, def, -kInf, kInf, false, false, choices, meaning, {}, true};
}
constexpr KeySpec textual(KeyType type, std::string_view name, std::string_view def, std::string_view meaning) {
  return {name, type, 0, def, -kInf, kInf, false, false, {}, meaning, {}, true};
}
}  // namespace detail

// clang-format off
inline constexpr KeySpec kKeys[] = {
    // camera: the colour camera (pinhole + Brown-Conrady distortion). Built-in default: TUM fr1 intrinsics without
    // distortion, what the synthetic generator renders.
    detail::positive("camera.fx", 517.3, 1e5, "focal length x (pixels); required in a settings file", "Camera1.fx|Camera.fx"),
    detail::positive("camera.fy", 516.5, 1e5, "focal length y (pixels); required in a settings file", "Camera1.fy|Camera.fy"),
    detail::real("camera.cx", 318.6, -1e5, 1e5, "principal point x (pixels); required in a settings file", "Camera1.cx|Camera.cx"),
    detail::real("camera.cy", 255.3, -1e5, 1e5, "principal point y (pixels); required in a settings file", "Camera1.cy|Camera.cy"),
    detail::real("camera.k1", 0.0, -1e3, 1e3, "radial distortion k1", "Camera1.k1|Camera.k1"),
    detail::real("camera.k2", 0.0, -1e3, 1e3, "radial distortion k2", "Camera1.k2|Camera.k2"),
    detail::real("camera.p1", 0.0, -1e3, 1e3, "tangential distortion p1", "Camera1.p1|Camera.p1"),
    detail::real("camera.p2", 0.0, -1e3, 1e3, "tangential distortion p2", "Camera1.p2|Camera.p2"),
    detail::real("camera.k3", 0.0, -1e3, 1e3, "radial distortion k3", "Camera1.k3|Camera.k3"),
    detail::integer("camera.width", 640, 1, 100000, "image width (pixels)", "Camera.width"),
    detail::integer("camera.height", 480, 1, 100000, "image height (pixels)", "Camera.height"),
    detail::positive("camera.fps", 30.0, 1000, "frame rate (Hz): pacing and the motion model's time step", "Camera.fps"),
    detail::optional_real("camera.baseline", 0.0, 10.0, "virtual stereo baseline (m) of the depth residual; when given, bf = fx * baseline", "(", "Stereo.b"),
    detail::positive("camera.bf", 40.0, 1e5, "fx times the virtual stereo baseline (pixels metres), used when camera.baseline is absent", "Camera.bf"),
    detail::real("camera.rolling_shutter_ms", 0.0, 0.0, 1000.0, "colour readout time from the first row to the last (ms): keypoints are moved to the middle row's instant, first with the motion model, then with the motion the frame's own pose solve measured (solved again); 0 = global shutter"),

    // depth: how raw depth becomes metres and how far it is trusted.
    detail::positive("depth.factor", 5000.0, 1e6, "raw depth units per metre (TUM/Bonn 5000, OpenLORIS/7-Scenes 1000)", "RGBD.DepthMapFactor|DepthMapFactor"),
    detail::positive("depth.th_depth", 40.0, 1e4, "close/far threshold in baselines (ORB-SLAM's ThDepth): points nearer than th_depth * baseline are close", "Stereo.ThDepth|ThDepth"),
    detail::real("depth.edge_ratio", 0.1, 0.0, 1.0, "keypoints on depth discontinuities keep no depth (colour and depth of real sensors are misregistered there); 0 = off"),
    detail::real("depth.disparity_weight", 10.0, 0.0, 1e4, "depth term of pose optimisation and BA: disparity bf/z with sigma 1/weight pixels; 0 = ORB-SLAM3's virtual-stereo residual"),
    detail::choice("depth.registration", "auto", "auto|off", "auto: check on 20 frames spread over the sequence whether depth is registered to colour and warp it into the colour camera when it clearly is not"),
    detail::real("depth.registration_max_baseline_m", 0.06, 0.0, 0.2, "auto registration: the baseline between depth and colour camera searched, +- metres along the image rows; 0 = zoom and shift only"),
    detail::optional_real("depth.camera_fx", 0.0, 1e5, "depth camera focal length x: when given (> 0), depth comes from this separate camera and is warped into the colour camera; 0 = none"),
    detail::optional_real("depth.camera_fy", 0.0, 1e5, "depth camera focal length y (default: depth.camera_fx)", "("),
    detail::optional_real("depth.camera_cx", -1e5, 1e5, "depth camera principal point x (default: camera.cx)"),
    detail::optional_real("depth.camera_cy", -1e5, 1e5, "depth camera principal point y (default: camera.cy)"),
    detail::real("depth.camera_tx", 0.0, -10.0, 10.0, "depth camera origin in the colour frame, x (m)"),
    detail::real("depth.camera_ty", 0.0, -10.0, 10.0, "depth camera origin in the colour frame, y (m)"),
    detail::real("depth.camera_tz", 0.0, -10.0, 10.0, "depth camera origin in the colour frame, z (m)"),

    // orb: the feature extractor.
    detail::integer("orb.n_features", 1000, 1, 100000, "ORB keypoints per frame", "ORBextractor.nFeatures"),
    detail::real("orb.scale_factor", 1.2, 1.0, 4.0, "scale between pyramid levels", "ORBextractor.scaleFactor", "("),
    detail::integer("orb.n_levels", 8, 1, 32, "pyramid levels", "ORBextractor.nLevels"),
    detail::integer("orb.ini_th_fast", 20, 1, 255, "FAST threshold tried first in each grid cell", "ORBextractor.iniThFAST"),
    detail::integer("orb.min_th_fast", 7, 1, 255, "FAST threshold where a cell finds nothing at ini_th_fast (at most ini_th_fast)", "ORBextractor.minThFAST"),
    detail::integer("orb.threads", 2, 1, 16, "threads extracting one frame's pyramid levels side by side (the caller and orb.threads - 1 helpers); the keypoints are the same for any count"),
    detail::choice("features.extractor", "ours", "ours|opencv", "ORB extractor: our own, or OpenCV's cv::ORB"),

    // tracking: frame pose estimation and the keyframe decision.
    detail::choice("tracking.kernel", "barron-fixed", "huber|barron-fixed|barron-adaptive|none", "robust kernel of frame pose optimisation (huber = ORB-SLAM3)"),
    detail::real("tracking.barron_alpha", -2.0, -10.0, 2.0, "Barron shape of the fixed kernel: -2 redescends (a box flying past stops pulling); the paper uses 1"),
    detail::positive("tracking.barron_c", 1.0, 1e3, "Barron scale on whitened residuals"),
    detail::positive("tracking.tau", 10.0, 1e3, "truncation of the log-partition table (barron-adaptive)"),
    detail::real("tracking.alpha_max", 2.0, -10.0, 2.0, "cap on the fitted alpha (barron-adaptive)"),
    detail::choice("tracking.alpha_fit", "norm", "norm|component", "what the adaptive alpha is fitted on: residual norms or components"),
    detail::flag("tracking.chi2_gates", true, "ORB-SLAM's chi-square outlier gates (5.991 / 7.815) on top of the kernel"),
    detail::positive("tracking.motion_radius", 15.0, 1000, "search radius (pixels at level 0) when matching against the last frame"),
    detail::integer("tracking.min_matches", 20, 3, 100000, "matches needed before a pose is optimised (motion model, reference keyframe)"),
    detail::real("tracking.motion_inlier_ratio", 0.5, 0.0, 1.0, "a motion-model pose keeping fewer inliers than this share of its matches is cross-checked against the reference keyframe"),
    detail::integer("tracking.established_found", 3, 0, 1000000, "frames a point must have been an inlier in to anchor the first pose round (0 = off)"),
    detail::integer("tracking.established_age", 10, 0, 1000000, "frames since creation a point needs to anchor the first pose round (0 = off)"),
    detail::flag("tracking.near_mover_check", true, "solve the pose on the far matches alone when the near ones (a mover close to the camera) move against them"),
    detail::real("tracking.near_mover_depth_ratio", 1.6, 1.0, 100.0, "the near-mover check splits matches by depth when the far cluster is this much deeper than the near one"),
    detail::real("tracking.near_mover_share", 0.3, 0.0, 1.0, "share of the near matches that must not fit the far pose for the near cluster to count as a mover"),
    detail::integer("tracking.near_mover_min_points", 30, 3, 100000, "matches each depth cluster needs before the near-mover check tests them"),
    detail::integer("tracking.near_mover_memory", 30, 0, 1000000, "frames a mover found by the near-mover check is followed after it last moved: its matches are left out of the first pose solve and its keypoints build no points (0 = not followed)"),
    detail::integer("tracking.min_inliers", 30, 3, 100000, "inliers after local-map tracking for a frame to count as tracked"),
    detail::integer("tracking.max_local_keyframes", 80, 1, 100000, "keyframes of the local map a frame is tracked against"),
    detail::integer("tracking.lost_frames_before_reinit", 3, 1, 1000000, "failed recoveries before a new map segment starts"),
    detail::integer("tracking.vo_points", 100, 0, 100000, "temporary depth points kept in the last frame (RGB-D visual odometry)"),
    detail::integer("tracking.close_keyframe_gap", 5, 1, 1000000, "frames between keyframes triggered by untracked close points"),
    detail::real("tracking.keyframe_inlier_ratio", 0.75, 0.0, 1.0, "a frame tracking fewer inliers than this share of its reference keyframe's points may become a keyframe"),
    detail::real("tracking.keyframe_urgent_ratio", 0.25, 0.0, 1.0, "below this share it becomes one even while the last keyframe is recent and mapping is busy"),
    detail::integer("tracking.keyframe_min_inliers", 15, 0, 100000, "a keyframe needs more inliers than this"),
    detail::integer("tracking.close_tracked_max", 100, 0, 100000, "with fewer close points tracked than this ..."),
    detail::integer("tracking.close_untracked_min", 70, 0, 100000, "... and more close points untracked than this, the frame adds structure: a keyframe (every close_keyframe_gap frames at most)"),

    // mapping: local mapping and Local BA.
    detail::choice("mapping.kernel", "barron-adaptive", "huber|barron-fixed|barron-adaptive|none", "robust kernel of Local BA (paper: barron-adaptive; huber = ORB-SLAM3)"),
    detail::real("mapping.barron_alpha", 1.0, -10.0, 2.0, "Barron shape (barron-fixed), and the starting alpha of barron-adaptive before any fit"),
    detail::positive("mapping.barron_c", 1.0, 1e3, "Barron scale on whitened residuals"),
    detail::positive("mapping.tau", 10.0, 1e3, "truncation of the log-partition table (barron-adaptive)"),
    detail::real("mapping.alpha_max", 1.0, -10.0, 2.0, "cap on the fitted alpha: 1 = pseudo-Huber, 2 = the paper's uncapped fit"),
    detail::choice("mapping.alpha_fit", "norm", "norm|component", "what the adaptive alpha is fitted on: residual norms (the paper) or components"),
    detail::flag("mapping.chi2_gates", true, "ORB-SLAM's chi-square outlier gates on top of the kernel"),
    detail::integer("mapping.ba_outer_iterations", 3, 1, 100, "alternations of alpha fit and solve per Local BA"),
    detail::integer("mapping.ba_iterations", 5, 1, 1000, "solver iterations per alternation"),
    detail::integer("mapping.ba_refine_iterations", 10, 0, 1000, "solver iterations of the refine solve on the gated inliers"),
    detail::choice("mapping.ba_solver", "schur", "schur|ceres", "Local BA solver: schur (dedicated Schur-complement Levenberg-Marquardt) or ceres (Ceres' sparse Schur); same step control, same solution, ceres about 3x slower"),
    detail::integer("mapping.triangulation_neighbours", 10, 1, 1000, "covisible keyframes searched for new points"),
    detail::integer("mapping.max_ba_keyframes", 20, 2, 10000, "keyframes optimised per Local BA (the most covisible); the others observing stay fixed"),
    detail::real("mapping.keyframe_redundancy", 0.9, 0.0, 1.0, "share of a keyframe's points seen by 3 other keyframes that makes it redundant", {}, "("),
    detail::real("mapping.min_found_ratio", 0.25, 0.0, 1.0, "new points found in fewer than this share of the frames that should see them are culled"),
    detail::flag("mapping.cull_keyframes", true, "remove redundant keyframes"),

    // loop: place recognition and loop correction.
    detail::flag("loop.enabled", true, "look for and close loops"),
    detail::integer("loop.min_keyframes", 10, 0, 1000000, "keyframes in the map before loops are sought"),
    detail::integer("loop.min_keyframe_gap", 10, 1, 1000000, "a candidate is at least this many keyframe ids older than the query"),
    detail::integer("loop.min_score", 30, 1, 256, "signature matches (of 256) for a place candidate"),
    detail::integer("loop.candidates", 3, 1, 100, "best place candidates verified per keyframe"),
    detail::integer("loop.min_ransac_inliers", 25, 3, 100000, "3-D/3-D RANSAC inliers against the candidate keyframe"),
    detail::integer("loop.min_inliers", 80, 3, 100000, "pose inliers after guided matching against the candidate's neighbourhood"),
    detail::integer("loop.keyframes_after_loop", 5, 0, 1000000, "keyframes skipped after a closure"),
    detail::real("loop.max_own_pose_share", 0.2, 0.0, 10.0, "refuse a loop whose side, matched from the keyframe's own pose, gives this share of the loop pose's inliers (a mover matched to itself); 0 = off"),
    detail::integer("loop.pose_graph_min_weight", 100, 1, 1000000, "covisibility weight for a pose-graph edge (besides the spanning tree)"),
    detail::flag("loop.global_ba", true, "global BA after each closed loop"),
    detail::integer("loop.global_ba_iterations", 10, 1, 1000, "iterations of that global BA"),
    detail::flag("loop.final_global_ba", false, "one global BA when the run ends"),
    detail::flag("loop.final_dense_refine", false, "when the run ends, align keyframes seen 5 s or more apart whose views overlap by dense ICP on their depth, and correct the keyframes' poses with those alignments (pose graph)"),

    // relocalization: recovery after tracking loss.
    detail::flag("relocalization.enabled", true, "relocalize against the place database when tracking is lost"),
    detail::integer("relocalization.min_score", 25, 1, 256, "signature matches (of 256) for a candidate keyframe"),
    detail::integer("relocalization.candidates", 5, 1, 100, "candidates tried per lost frame"),
    detail::integer("relocalization.min_inliers", 30, 3, 100000, "pose inliers against the candidate keyframe"),
    detail::integer("relocalization.loaded_map_min_inliers", 10, 3, 100000, "the same in a map this session did not build (a loaded map, localization only): a place is rarely seen from one keyframe alone; relocalization.loaded_map_check_inliers verifies the fix"),
    detail::integer("relocalization.loaded_map_check_inliers", 40, 10, 100000, "local-map inliers that confirm a fix in a map this session did not build (after any other recovery: relocalization.check_inliers); between mapped viewpoints fewer of the map's points match"),
    detail::integer("relocalization.loaded_map_min_score", 12, 1, 256, "relocalization.min_score in a map this session did not build (a loaded map, localization only)"),
    detail::integer("relocalization.loaded_map_candidates", 20, 1, 1000, "relocalization.candidates in a map this session did not build; candidates inside a neighbourhood already tried are skipped"),
    detail::integer("relocalization.neighbourhood_keyframes", 10, 0, 1000, "covisible keyframes whose map points join a candidate's when one keyframe alone does not locate the frame in a map this session did not build"),
    detail::integer("relocalization.loaded_map_patience", 90, 1, 1000000,
                    "frames a run started on a loaded map tries to relocalize in it before starting a new segment"),
    detail::integer("relocalization.check_inliers", 50, 10, 100000, "local-map inliers that confirm a recovery or relocalization in this session's own map"),
    detail::integer("relocalization.lost_views", 6, 0, 100, "while lost in a map this session did not build, frames chained by visual odometry (one per 1 cm or 1 degree of motion) whose points are matched together when one frame alone does not locate (0: off)"),
    detail::flag("relocalization.place_back_lost_frames", true, "once a frame is located in a map this session did not build, the frames lost before it get poses in the final trajectory from the fix, along their visual odometry (never live poses)"),

    // semantic: the person detector and the depth-aware keypoint filter.
    detail::choice("semantic.detector", "auto", "auto|yolo|boxes|hog|none", "person detector: auto (yolo when its model is found, else none, said once), yolo (OpenCV dnn), boxes (a boxes file), hog, none (no person filter)"),
    detail::textual(KeyType::Text, "semantic.model", "yolo-fastest-1.1_body", "YOLO preset (yolo-fastest-1.1_body: one class, a person; yolo-fastest-1.1-xl: 80 COCO classes, 2-2.5x the cost), looked up in model_dir, $VARSLAM_MODELS, ./models, ../shared/models, <install>/share/varslam/models"),
    detail::textual(KeyType::Path, "semantic.model_dir", "", "folder searched first for the model files"),
    detail::textual(KeyType::Path, "semantic.model_cfg", "", "Darknet cfg (with model_weights; instead of a preset)"),
    detail::textual(KeyType::Path, "semantic.model_weights", "", "Darknet weights or an ONNX file (instead of a preset)"),
    detail::textual(KeyType::Path, "semantic.names_file", "", "class names, one per line (default: COCO's)"),
    detail::integer("semantic.input_size", 320, 32, 4096, "network input size (a multiple of 32)"),
    detail::real("semantic.conf_threshold", 0.3, 0.0, 1.0, "detection confidence threshold"),
    detail::real("semantic.nms_threshold", 0.45, 0.0, 1.0, "non-maximum suppression overlap", {}, "("),
    detail::textual(KeyType::TextList, "semantic.classes", "person", "labels kept (after aliasing)"),
    detail::textual(KeyType::TextMap, "semantic.label_aliases", "body:person", "labels renamed before the class test"),
    detail::integer("semantic.num_threads", 1, 0, 256, "OpenCV threads of the detector (0 = OpenCV's choice)"),
    detail::textual(KeyType::Path, "semantic.boxes_file", "boxes.txt", "boxes file of detector: boxes (one line per box: timestamp label score x y w h); relative: to the dataset folder, then to the settings file"),
    detail::real("semantic.boxes_max_dt", 0.02, 0.0, 10.0, "largest timestamp gap (s) to still use a frame's boxes from the boxes file"),
    detail::real("semantic.box_enlarge", 0.1, 0.0, 2.0, "fraction of width and height added on each side of a box", {}, ")"),
    detail::positive("semantic.depth_band_m", 0.5, 10.0, "keypoints within this distance (m) of the person depth are dropped"),
    detail::real("semantic.min_depth_m", 0.1, 0.0, 100.0, "depths below count as invalid"),
    detail::positive("semantic.max_depth_m", 20.0, 1000.0, "depths above count as invalid"),
    detail::positive("semantic.bin_m", 0.1, 10.0, "histogram bin width (m) for the person-depth mode"),
    detail::real("semantic.peak_fraction", 0.15, 0.0, 1.0, "share of a box's depth samples a histogram peak needs", {}, "("),
    detail::integer("semantic.sample_step", 2, 1, 64, "depth samples every n-th pixel inside a box"),
    detail::real("semantic.silhouette_margin_px", 0.0, 0.0, 1000.0, "drop background keypoints this close (pixels) to the person's pixels; 0 = off"),
    detail::real("semantic.min_exclusive_share", 1.0, 0.0, 1.0, "overlapping boxes also get a person depth from their own part when it holds this share; 1 = off"),
    detail::flag("semantic.asynchronous", true, "real-time mode: detection on its own thread, tracking uses the freshest boxes (deterministic mode follows semantic.deterministic_detect_every and _lag)"),
    detail::flag("semantic.propagate_boxes", true, "shift stale boxes by optical flow"),
    detail::integer("semantic.deterministic_detect_every", 0, 0, 5, "deterministic mode: the detector runs on every n-th frame (on its own thread) and the frames between use its boxes carried over by optical flow; 0 = 1 for a boxes file (it costs nothing), 2 for a detector that computes"),
    detail::integer("semantic.deterministic_detect_lag", -1, -1, 5, "deterministic mode: a frame's detections are taken this many frames later (the detector runs meanwhile, beside tracking); 0 = on the frame itself; -1 = the frames between detections minus one; at most semantic.deterministic_detect_every"),
    detail::flag("semantic.mask_extraction", true, "extract no keypoints on the people, so their share of the budget goes to the background"),

    // dense: the dense map of the static scene (a TSDF fused from the keyframes' depth, movers left out).
    detail::flag("dense.enabled", false, "fuse the keyframes' depth into a dense map of the static scene (`varslam run --dense-map` sets it; outputs dense_mesh.ply and dense_map.bt)"),
    detail::real("dense.voxel_size", 0.02, 0.005, 0.5, "voxel edge (m) of the dense map and of its occupancy map"),
    detail::real("dense.truncation_voxels", 4.0, 1.0, 50.0, "truncation distance of the signed distance, in voxels"),
    detail::real("dense.min_range", 0.2, 0.0, 100.0, "depth (m) below which a pixel is not fused"),
    detail::positive("dense.max_range", 4.0, 100.0, "depth (m) beyond which a pixel is not fused (above dense.min_range)"),
    detail::integer("dense.min_weight", 1, 1, 1000, "observations a voxel needs to be part of the mesh and the occupancy map"),
    detail::integer("dense.pixel_step", 2, 1, 16, "fuse every n-th pixel of a keyframe in each direction (the keyframe store shrinks by its square)"),
    detail::flag("dense.clear_free_space", true, "space a depth pixel sees through (beyond the truncation in front of its surface) is voted free, so a mover fused once and seen through later is removed"),
    detail::integer("dense.keep_free_votes", 2, 0, 1000, "a voxel seen only as free space at least this many times stays free when a surface shows up in it (a mover no filter knew walked in); 0 = off"),
    detail::flag("dense.exclude_movers", true, "leave out the pixels the system knows moved: people at their depth band, the near mover followed, keypoints flagged moving, the caller's mover mask (false: fuse every pixel)"),
    detail::real("dense.moving_point_radius_px", 12.0, 0.0, 200.0, "radius (pixels) of the disc left out around a keypoint flagged moving (at its depth)"),
    detail::integer("dense.mover_margin_px", 3, 0, 100, "the mover mask grows by this many pixels (the mixed depths at a mover's outline)"),
    detail::positive("dense.reintegrate_m", 0.01, 10.0, "real-time mode: a keyframe whose pose moved this far (m) since it was fused is fused again"),
    detail::positive("dense.reintegrate_deg", 0.5, 180.0, "... or turned this much (degrees)"),

    // eval: how a run's trajectory is compared with the dataset's ground truth.
    detail::choice("eval.groundtruth_camera", "colour", "colour|depth", "the camera the ground truth poses are of: colour, or depth (a separate depth camera, e.g. 7-Scenes' KinectFusion poses): the estimate is then moved by the depth camera's offset before ATE/RPE (registered depth: the same camera)"),
};
// clang-format on

/// Sections of the registry (the part of a key before the dot), in table order.
inline constexpr std::string_view kSections[] = {"camera",   "depth", "orb",            "features", "tracking",
                                                 "mapping",  "loop",  "relocalization", "semantic",
                                                 "dense",    "eval"};

/// ORB-SLAM3 / ORB-SLAM2 keys that varslam reads nothing from: accepted in settings files, never an error.
/// An entry ending in '.' covers every key with that prefix.
inline constexpr std::string_view kIgnoredForeignKeys[] = {
    "File.version", "Camera.RGB", "Camera.newWidth", "Camera.newHeight", "Camera.bFishEye",
    "Stereo.T_c1_c2", "Tbc", "Viewer.", "System.", "IMU.", "Camera2.", "LoopClosing.", "Tracking.", "PointCloudMapping."};

constexpr std::span<const KeySpec> all() { return kKeys; }

/// Position of the key in kKeys; std::size(kKeys) when it is not declared.
constexpr std::size_t key_index(std::string_view name) {
  for (std::size_t i = 0; i < std::size(kKeys); ++i)
    if (kKeys[i].name == name) return i;
  return std::size(kKeys);
}

/// The same for `section` + "." + `key` (a stage's keys, looked up by section).
constexpr std::size_t key_index(std::string_view section, std::string_view key) {
  for (std::size_t i = 0; i < std::size(kKeys); ++i) {
    const std::string_view n = kKeys[i].name;
    if (n.size() == section.size() + 1 + key.size() && n.substr(0, section.size()) == section &&
        n[section.size()] == '.' && n.substr(section.size() + 1) == key)
      return i;
  }
  return std::size(kKeys);
}

/// The key's declaration; nullptr when it is not declared.
constexpr const KeySpec* find(std::string_view name) {
  const std::size_t i = key_index(name);
  return i == std::size(kKeys) ? nullptr : &kKeys[i];
}

/// Compile-time defaults for the config structs: a name that is not declared, or of another type, does not compile.
/// (By value and by index: GCC's sanitizer instrumentation rejects pointer tests in constant evaluation.)
consteval KeySpec spec(std::string_view name) {
  const std::size_t i = key_index(name);
  if (i == std::size(kKeys)) throw "setting_keys: key not declared in kKeys";
  return kKeys[i];
}
consteval int int_default(std::string_view name) {
  const KeySpec k = spec(name);
  if (k.type != KeyType::Int) throw "setting_keys: not an integer key";
  return static_cast<int>(k.number);
}
consteval double real_default(std::string_view name) {
  const KeySpec k = spec(name);
  if (k.type != KeyType::Real || !k.has_default) throw "setting_keys: not a real key with a default";
  return k.number;
}
consteval bool bool_default(std::string_view name) {
  const KeySpec k = spec(name);
  if (k.type != KeyType::Bool) throw "setting_keys: not a boolean key";
  return k.number != 0.0;
}
consteval std::string_view text_default(std::string_view name) {
  const KeySpec k = spec(name);
  if (k.type == KeyType::Int || k.type == KeyType::Real || k.type == KeyType::Bool)
    throw "setting_keys: not a text key";
  return k.text;
}

/// Defaults of list and map keys ("a,b" and "from:to,from:to" in the table) as the structs hold them.
inline std::vector<std::string> list_default(std::string_view name) {
  std::vector<std::string> out;
  std::string_view text = find(name)->text;
  while (!text.empty()) {
    const auto comma = text.find(',');
    out.emplace_back(text.substr(0, comma));
    text = comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
  }
  return out;
}
inline std::map<std::string, std::string> map_default(std::string_view name) {
  std::map<std::string, std::string> out;
  for (const std::string& pair : list_default(name)) {
    const auto colon = pair.find(':');
    out[pair.substr(0, colon)] = colon == std::string::npos ? std::string() : pair.substr(colon + 1);
  }
  return out;
}

}  // namespace varslam::setting_keys
