#pragma once
// varslam::Slam: one SLAM session (C++17). Feed it colour + depth frames; it returns each frame's pose at once and
// maps, closes loops and relocalizes behind it. Conventions (frames, axes, units, timestamps): <varslam/types.hpp>.
//
// Threads. track(), finish(), reset(), load_map() and set_localization_only() are called from one thread (the
// "tracking thread"). From any other thread, at any time, these may be called while track() runs: map_snapshot(),
// live_trajectory(), save_map(), summary(). Listener callbacks run on the tracking thread, inside track() or
// finish(); they must not call back into the session.
#include <memory>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <varslam/config.hpp>
#include <varslam/error.hpp>
#include <varslam/types.hpp>
#include <vector>

namespace varslam {

enum class Mode {
  Deterministic,  // every stage in the caller's thread: the same input gives the same output (tests, benchmarks)
  RealTime,       // local mapping, loop closing and the person detector on their own threads: track() never waits
                  // for a Local BA
};

/// What the session reports besides the poses. Override what you need.
class Listener {
 public:
  virtual ~Listener() = default;
  virtual void on_local_ba(const LocalBaInfo&) {}
  virtual void on_loop(const LoopInfo&) {}
  virtual void on_person_boxes(const PersonBoxesInfo&) {}
};

/// The live viewer: a page to open in a browser showing the map, the image with its keypoints, the person boxes and
/// the Local BA alpha as the session runs (frames are sent only while a browser is connected).
struct ViewerOptions {
  int port = 0;                       // 0: a free one
  std::string address = "127.0.0.1";  // another interface makes the session visible to the network
  double max_frame_rate = 15;         // frames per second sent at most
  std::string title;                  // what the page names the run
};

struct SessionSummary {
  std::size_t frames = 0, tracked = 0, keyframes = 0, map_points = 0;
  int segments = 0, relocalizations = 0;
  std::string person_detector;  // "none" without the person filter
};

/// What a frame may bring besides its images.
struct FrameExtras {
  /// The people in this image from the caller's own detector (as track(bgr, depth, timestamp, people) takes them).
  std::optional<std::vector<PersonBox>> people;
  /// The caller's own segmentation of things that move: CV_8UC1 of the image's size, non-zero on movers. No keypoints
  /// are taken there, so nothing is tracked on or mapped from them. Empty: none. Applies to this frame only.
  cv::Mat mover_mask;
};

class Slam {
 public:
  /// Throws ConfigError for bad settings and InputError when the person detector's model cannot be loaded.
  explicit Slam(const Config& config, Mode mode = Mode::Deterministic);
  ~Slam();  // stops the worker threads (finish() first to keep the map complete)
  Slam(const Slam&) = delete;
  Slam& operator=(const Slam&) = delete;

  /// Tracks one frame. Throws InputError for an image of the wrong size or type, or a timestamp that is not
  /// finite or not after the previous frame's (the frame is then not used; the session goes on). The session may
  /// keep the images after the call (the person detector's and the viewer's threads): do not write into them
  /// afterwards. A matrix over your own buffer (no OpenCV reference count) is copied, so the buffer may be reused.
  TrackedFrame track(const cv::Mat& bgr, const cv::Mat& depth, double timestamp);
  /// The same with the people in this image from the caller's own detector (the person filter uses them as they are).
  TrackedFrame track(const cv::Mat& bgr, const cv::Mat& depth, double timestamp, const std::vector<PersonBox>& people);
  /// The same with a mover mask and/or person boxes. InputError for a mask of another size or type.
  TrackedFrame track(const cv::Mat& bgr, const cv::Mat& depth, double timestamp, const FrameExtras& extras);

  /// Finishes local mapping and loop closing so the map and camera_trajectory() are final. Later track() calls are
  /// an error (reset() starts again).
  void finish();
  /// Forgets the map and trajectories and starts again with the same settings (a loaded map is loaded again, and
  /// localization-only stays on; without a loaded map it goes off).
  void reset();

  /// Starts from a map saved by save_map(): the session is reset and the next frames relocalize in the map. The map
  /// brings its camera. Throws InputError naming the file when it is not a usable map.
  void load_map(const std::string& file);
  /// Tracks in the map without extending it (no keyframes, no points): the live pose in a known map.
  void set_localization_only(bool on);
  /// Where the camera is, roughly (camera-to-world in the map's frame: from odometry, or a place picked on the map):
  /// while tracking is lost, or not yet found in a loaded map, the keyframes within `radius_m` of it are tried first
  /// and a fix is kept only within `radius_m` of it; the place database is searched after them as usual. Kept until a
  /// frame is tracked; it does not move a pose that tracking holds. InputError for a non-finite pose, a quaternion far
  /// from unit length or a radius that is not positive.
  void relocalize_near(const Pose& camera_to_world, double radius_m = 1.0);
  /// Writes the map (atomically). While running in real-time mode, local mapping pauses until its queue is drained
  /// (about one Local BA) so the copy is consistent; tracking waits meanwhile.
  void save_map(const std::string& file);

  /// The latest consistent copy of the map, refreshed after every keyframe and whenever a caller asked since the
  /// last frame (so it is at most one frame old).
  std::shared_ptr<const MapSnapshot> map_snapshot() const;
  /// The dense map of the static scene; empty (no keyframes) unless the settings say `dense.enabled: true`. From any
  /// thread. Real-time mode: the map the dense-map thread holds now (each keyframe fused at the pose it had then, and
  /// again when Local BA or a loop moved it). Deterministic mode: fused from the keyframes' current poses on the call
  /// (it takes as long as fusing every keyframe). After finish(): fused from the final poses.
  std::shared_ptr<const DenseMapSnapshot> dense_map_snapshot() const;
  /// The parts of the dense map `request` asks for (ConfigError naming the field for a bad one). With only the
  /// surface asked for, deterministic mode fuses just the keyframes new since the last call (and those whose pose
  /// moved) instead of every keyframe, and what finish() writes does not change.
  std::shared_ptr<const DenseMapSnapshot> dense_map_snapshot(const DenseMapRequest& request) const;
  /// Each frame's pose as tracking gave it (a copy).
  std::vector<TimedPose> live_trajectory() const;
  /// Every tracked frame's pose after every correction so far (Local BA, loops). Tracking thread, or after finish().
  /// In a loaded map, frames lost before the first fix are in it too, placed back from the fix by visual odometry
  /// (relocalization.place_back_lost_frames); live_trajectory() never has them.
  std::vector<TimedPose> camera_trajectory() const;
  SessionSummary summary() const;

  /// Starts the live viewer for this session (it stays up across reset() and load_map()) and returns the address to
  /// open. InputError when it cannot listen, its page's files are missing, or this build has no viewer. Tracking
  /// thread.
  std::string start_viewer(const ViewerOptions& options = {});

  /// Not owned; must outlive the session or be removed first. Tracking thread only.
  void add_listener(Listener& listener);
  void remove_listener(Listener& listener);

  Mode mode() const;
  /// The library's version, e.g. "0.1.0".
  static std::string version();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace varslam
