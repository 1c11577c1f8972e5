#pragma once
// varslam::Pipeline: the whole system of the paper behind one object. Settings -> depth registration -> person
// detector + depth-aware keypoint filter + extraction mask -> tracking -> local mapping -> loop closing, in
// deterministic mode (every stage in the caller's thread: same input, same output) or real-time mode (local
// mapping and the detector on their own threads). Feed it colour + depth + timestamp; it returns the pose and
// reports everything else to observers (pipeline/events.hpp). It never prints (the stages log through spdlog).
//
//   varslam::Pipeline slam(varslam::load_settings("settings.yaml"));
//   for (...) { const varslam::FrameResult r = slam.track(bgr, depth16, t); if (r.T_wc) use(*r.T_wc); }
//   slam.finish();
//   const varslam::Trajectory traj = slam.camera_trajectory();
#include <filesystem>
#include <memory>
#include <optional>
#include <mutex>
#include <span>
#include <vector>

#include "core/rgbd_frame.hpp"
#include "core/trajectory.hpp"
#include "io/settings.hpp"
#include "pipeline/events.hpp"
#include "semantic/detector.hpp"
#include "semantic/detector_settings.hpp"
#include "slam/config.hpp"
#include "slam/system.hpp"

namespace varslam {

using slam::RunMode;

/// The library's version (the CMake project version).
inline constexpr std::string_view kVersion = VARSLAM_VERSION_STRING;

namespace semantic {
class DynamicKeypointMasker;
}
namespace dense {
class DenseMapper;
struct DenseConfig;
struct MoverMaskInputs;
}

struct PipelineOptions {
  RunMode mode = RunMode::Deterministic;
  /// A person detector of the caller's own, used instead of the one `semantic.detector` names. In real-time mode
  /// with semantic.asynchronous it runs on the detector's thread.
  std::shared_ptr<semantic::Detector> detector;
};

/// Facts about the whole run so far (on request).
struct PipelineSummary {
  std::size_t frames = 0, tracked = 0, keyframes = 0, map_points = 0;
  int segments = 0, relocalizations = 0;
  int placed_back = 0;  // lost frames placed in the final trajectory from a later fix (relocalization.place_back_lost_frames)
  long near_mover_solves = 0;  // pose solves the near-mover check changed (tracking.near_mover_check)
  std::string detector;        // "none" without the person filter
  long detector_runs = 0;
  bool detector_asynchronous = false;
};

class Pipeline {
 public:
  /// Throws ConfigError for bad settings and InputError when the detector's model cannot be loaded.
  explicit Pipeline(const Settings& settings, PipelineOptions options = {});
  ~Pipeline();  // stops the worker threads (finish() first to keep the map complete)
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// Observers get every event from now on, in the order added. Not owned: each must outlive the pipeline or be
  /// removed first. An observer may add or remove observers from a callback, but not call track() or finish().
  void add_observer(Observer& observer);
  void remove_observer(Observer& observer);

  /// Optional, before the first frame: decide depth registration (`depth.registration: auto`) on these frames
  /// (about 10 spread over the sequence is what the CLI uses). Without it, the first tracked frame decides alone.
  void calibrate_depth(std::span<const RgbdFrame> samples);
  /// True when calibrate_depth() looks at its samples (`depth.registration: auto` and no depth.camera_* given).
  bool wants_depth_samples() const { return cfg_.tracking.estimate_registration && !cfg_.tracking.depth_rig; }
  /// What a loader thread may apply to each frame before track() (thread-safe; valid after calibrate_depth()):
  /// warps unregistered depth into the colour camera. track() does it itself for frames that did not get it.
  std::function<void(RgbdFrame&)> frame_preparation() const;

  /// Before the first frame: start from a map saved by save_map() (the first frames relocalize in it). Throws
  /// InputError naming the file when it is not a usable map or was built with another camera or ORB pyramid.
  void load_map(const std::filesystem::path& file);
  /// Track against the map without extending it (no keyframes, no points, no new segment): the live pose in a
  /// known map, as a robot uses it. Needs a loaded map when switched on before the first frame.
  void set_localization_only(bool on);
  /// While tracking is lost (or not yet fixed in a loaded map), relocalize near this camera-to-world pose first
  /// (slam::Tracker::set_pose_hint). Kept until a frame is tracked.
  void relocalize_near(const Eigen::Isometry3d& T_wc, double radius_m);
  /// Writes the map (atomically): after finish(), or between track() calls (real-time mode: local mapping is
  /// paused until its queue is drained, then resumed). `groundtruth_alignment` (map frame -> ground-truth frame), when
  /// the caller has one, goes with it so runs in this map can be evaluated in its frame.
  void save_map(const std::filesystem::path& file,
                const std::optional<Eigen::Isometry3d>& groundtruth_alignment = std::nullopt);
  /// Local mapping has nothing to do right now: a copy taken now does not wait for it.
  bool mapping_idle() const { return !system_ || system_->mapping_idle(); }
  /// The copy save_map() writes (`file` names it in errors), for a caller that writes it outside its own lock.
  slam::SavedMap map_to_save(const std::filesystem::path& file,
                             const std::optional<Eigen::Isometry3d>& groundtruth_alignment = std::nullopt);
  /// The loaded map's alignment to ground truth, when it has one.
  const std::optional<Eigen::Isometry3d>& loaded_map_alignment() const { return loaded_alignment_; }
  /// The separate depth camera depth is warped from (given in the settings or found on the first frames); nullopt
  /// when depth is registered to colour.
  const std::optional<DepthCameraRig>& depth_rig() const { return cfg_.tracking.depth_rig; }

  /// Tracks one frame. `bgr`: CV_8UC3 (or CV_8UC1 gray); `depth`: CV_16UC1 raw (divided by depth.factor) or
  /// CV_32FC1 metres, 0 = no depth; both of the camera's size. `boxes`: the people in this image from the caller's
  /// own detector (the person filter then uses them as they are). `mover_mask`: optional CV_8UC1 of the image's
  /// size, non-zero where movers are (no keypoints are taken there).
  FrameResult track(const cv::Mat& bgr, const cv::Mat& depth, double timestamp,
                    const std::optional<Detections>& boxes = std::nullopt, const cv::Mat& mover_mask = cv::Mat());
  /// The same for a decoded frame (dataset readers): gray CV_8UC1 (bgr optional, for the detector) and depth
  /// CV_32FC1 in metres, of the camera's size; InputError otherwise.
  FrameResult track(const RgbdFrame& frame, const std::optional<Detections>& boxes = std::nullopt);

  /// Finishes local mapping and loop closing so the map and trajectories are final; rethrows an error a worker
  /// thread stopped on. Later track() calls are an error.
  void finish();

  /// Camera-to-world pose of every tracked frame, after every correction so far (BA, loops).
  /// `repaired` (optional) gets how many final poses no frame supported were replaced (slam/trajectory_guard.hpp).
  Trajectory camera_trajectory(int* repaired = nullptr) const;
  /// Each pose as tracking gave it (what a live user got).
  const Trajectory& live_trajectory() const { return live_; }
  Trajectory keyframe_trajectory() const;
  const slam::Map& map() const;
  PipelineSummary summary() const;
  /// The dense map of the static scene (dense.enabled), null when off or before the first frame. Final after
  /// finish(); its mesh()/occupancy()/stats() may be read from any thread.
  dense::DenseMapper* dense_map() const { return dense_.get(); }
  std::shared_ptr<dense::DenseMapper> shared_dense_map() const { return dense_; }

  const Settings& settings() const { return settings_; }  // camera = the colour camera after registration
  const slam::SlamConfig& config() const { return cfg_; }
  RunMode mode() const { return options_.mode; }

 private:
  class Relay;  // takes the stages' records (any thread) and queues them for the observers
  void start(std::span<const RgbdFrame> samples);
  void install_person_filter();
  void adopt_map_camera(DepthRegistrationEvent& reg);
  void deliver_queued();
  template <typename Event, typename Fn>
  void emit(const Event& e, Fn fn);

  Settings settings_;
  slam::SlamConfig cfg_;
  PipelineOptions options_;
  semantic::SemanticSettings semantic_;
  std::vector<Observer*> observers_;
  std::unique_ptr<Relay> relay_;
  std::unique_ptr<semantic::DynamicKeypointMasker> masker_;
  std::optional<DetectionEvent> detection_;  // of the frame being tracked, handed out after it
  std::unique_ptr<slam::System> system_;     // built by start(), once the colour camera is known
  std::unique_ptr<dense::DenseConfig> dense_cfg_;
  std::shared_ptr<dense::DenseMapper> dense_;  // dense.enabled: built by start() (it needs the colour camera)
  void give_dense_keyframe(const RgbdFrame& frame, const slam::TrackOutcome& out);
  void keep_keyframe_depth(const RgbdFrame& frame, const slam::TrackOutcome& out);
  dense::MoverMaskInputs named_mover_inputs(const RgbdFrame& frame) const;
  dense::MoverMaskInputs mover_inputs(const RgbdFrame& frame, const slam::TrackOutcome& out) const;
  const slam::Map empty_map_;               // what map() shows before the first frame
  Trajectory live_;
  std::optional<mapfile::SavedMap> pending_map_;  // loaded, adopted when the system starts
  std::filesystem::path pending_map_file_;
  std::optional<Eigen::Isometry3d> loaded_alignment_;
  bool localization_only_ = false;
  std::optional<std::pair<Eigen::Isometry3d, double>> pending_pose_hint_;  // given before the system started
  std::size_t frames_ = 0, tracked_ = 0;
  bool finished_ = false;
};

}  // namespace varslam
