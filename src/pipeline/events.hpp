#pragma once
// What the pipeline reports while it runs. Observers receive every event on the thread that calls
// Pipeline::track() / Pipeline::finish() (work done on the mapping thread is queued and handed over there), so an
// observer needs no locking of its own; one that does slow work (a viewer, a network sender) should copy what it
// needs and hand it to its own thread.
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "core/detection.hpp"
#include "semantic/keypoint_filter.hpp"
#include "slam/system_events.hpp"
#include "slam/tracking.hpp"

namespace varslam {

using slam::TrackState;

/// One frame through tracking: what Pipeline::track() returns and on_frame() receives.
struct FrameResult {
  std::size_t index = 0;  // frames given to the pipeline before this one
  double timestamp = 0;
  TrackState state = TrackState::NotInitialized;
  bool keyframe = false;     // the frame became a keyframe
  long keyframe_id = -1;
  bool new_segment = false;  // tracking was lost and a new map segment started here
  int keypoints = 0, keypoints_with_depth = 0, inliers = 0, depth_edge_rejected = 0;
  slam::FrameTimings timings;
  slam::PoseResiduals residuals;  // of the inlier matches at the pose tracking solved (empty when not solved)
  // The pose tracking gave the frame, camera-to-world (what a robot uses live); empty when it was not tracked.
  std::optional<Eigen::Isometry3d> T_wc;
  std::size_t map_keyframes = 0, map_points = 0;  // size of the map after this frame
  std::size_t mapping_queue = 0;  // keyframes waiting for local mapping after this frame (real time)
};

/// The person stage on one frame: the boxes used and which keypoints the depth-aware filter dropped.
struct DetectionEvent {
  std::size_t index = 0;         // as FrameResult::index
  std::size_t source_index = 0;  // RgbdFrame::index of the frame (a dataset's frame number)
  double timestamp = 0;
  bool have_detections = false;  // false until the detector finished its first frame
  double box_age_s = 0;          // frame time - time of the image the boxes were found in
  double detector_latency_s = 0;
  bool propagated = false;       // stale boxes were moved onto this frame by optical flow
  Detections boxes;
  semantic::PersonRegions people;  // the boxes as the filter used them, with each person's depth (0 = unknown)
  float depth_band_m = 0;          // keypoints within +-band of a person's depth were dropped
  semantic::FilterStats stats;
  std::vector<cv::KeyPoint> keypoints;  // all keypoints of the frame (level-0 pixels)
  std::vector<bool> keep;               // per keypoint: false where the filter dropped it
  cv::Mat bgr;                          // the frame's colour image (shared, not copied: do not write to it)
};

/// The tracked frame's keypoints and what tracking made of each (a viewer's overlay, debugging).
struct KeypointsEvent {
  std::size_t index = 0;  // as FrameResult::index
  double timestamp = 0;
  std::shared_ptr<const slam::FrameFeatures> features;  // undistorted positions, depth, on_depth_edge; after the filter
  std::vector<slam::KeypointFate> fate;                 // per keypoint of `features`
  cv::Mat image;  // the frame's colour image (gray when only gray was given); shared, do not write to it
};

/// A frame that became a keyframe.
struct KeyframeEvent {
  long keyframe_id = 0;
  std::size_t frame_index = 0;
  double timestamp = 0;
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();  // as tracking placed it
  bool new_segment = false;  // the first keyframe of a new map segment (tracking was lost before it)
  cv::Mat depth;  // the frame's depth (CV_32FC1 metres, in the colour camera); shared, do not write to it
};

/// Tracking found its place again by global relocalization.
struct RelocalizationEvent {
  std::size_t frame_index = 0;
  double timestamp = 0;
  slam::Relocalization relocalization;
};

/// Depth registration, decided once before the first frame (depth.registration).
struct DepthRegistrationEvent {
  std::string mode;  // "off", "settings" (depth.camera_* given), "auto"
  bool found = false;  // auto: depth was found unregistered and is warped into the colour camera
  double scale = 1, du = 0, dv = 0, score = 0, identity_score = 0, ms = 0;
  double baseline_x = 0;  // the depth camera's origin in the colour frame along x (m)
  int frames = 0;
  std::optional<PinholeCamera> colour_camera;  // the colour camera estimated (found)
};

class Pipeline;

class Observer {
 public:
  virtual ~Observer() = default;
  /// From Pipeline::add_observer: the pipeline now observed (its map and trajectories may be read from a callback).
  virtual void on_added(const Pipeline&) {}
  /// From Pipeline::finish(), last: the map and trajectories are final.
  virtual void on_finished() {}
  virtual void on_depth_registration(const DepthRegistrationEvent&) {}
  virtual void on_frame(const FrameResult&) {}
  virtual void on_detection(const DetectionEvent&) {}
  virtual void on_keypoints(const KeypointsEvent&) {}
  virtual void on_keyframe(const KeyframeEvent&) {}
  /// Local mapping finished a keyframe; its Local BA (alpha per iteration, fitted and applied) is in `ba`.
  virtual void on_keyframe_mapped(const slam::KeyframeMapped&) {}
  virtual void on_loop_search(const slam::LoopSearch&) {}
  virtual void on_loop(const slam::LoopRecord&) {}
  virtual void on_relocalization(const RelocalizationEvent&) {}
};

}  // namespace varslam
