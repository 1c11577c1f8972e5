#pragma once
// The whole semantic stage for the tracker, one call per frame: submit the frame to the (asynchronous) detector,
// take the freshest boxes, move them onto this frame if they are older, and run the depth-aware filter.
#include <deque>
#include <memory>
#include <optional>

#include "core/rgbd_frame.hpp"
#include "semantic/async_detector.hpp"
#include "semantic/detector_settings.hpp"
#include "semantic/keypoint_filter.hpp"

namespace varslam::semantic {

struct MaskResult {
  std::vector<bool> keep;  // one per keypoint
  FilterStats stats;
  Detections boxes;            // as used on this frame (after propagation)
  bool have_detections = false;  // false until the detector finished its first frame
  double staleness_s = 0.0;    // frame time - time of the image the boxes were detected in
  double detector_latency_s = 0.0;
  bool propagated = false;
  PersonRegions people;  // the boxes as the filter used them (enlarged, clipped) with each person's depth
};

class DynamicKeypointMasker {
 public:
  /// Throws InputError from make_detector() (e.g. a missing model file).
  explicit DynamicKeypointMasker(const SemanticSettings& settings);
  /// Takes an already built detector (tests, custom detectors).
  DynamicKeypointMasker(std::unique_ptr<Detector> detector, const SemanticSettings& settings);

  /// frame.bgr (or gray) feeds the detector, frame.gray the box propagation, frame.depth the filter.
  MaskResult process(const RgbdFrame& frame, const std::vector<cv::KeyPoint>& kps);

  /// The pixels where keypoints are worth extracting on this frame (allowed_pixels of its boxes; empty when there
  /// are none). Call before process() on the same frame: both use the same boxes, found once.
  cv::Mat extraction_mask(const RgbdFrame& frame);

  /// Boxes for the next frame processed, given by the caller (e.g. from its own detector): that frame uses them
  /// as they are, and the detector does not run on it.
  void give_boxes(std::optional<Detections> boxes) { given_ = std::move(boxes); }

  /// Blocks until the detector has finished every submitted frame.
  void wait_for_detector() { async_.wait_idle(); }
  std::string detector_name() const { return async_.name(); }
  long detector_runs() const { return async_.processed(); }

 private:
  struct PastGray {
    double timestamp;
    cv::Mat gray;
  };
  /// Submits the frame to the detector, takes the freshest boxes, moves them onto the frame and locates the people
  /// in its depth; once per frame (current_, people_).
  void boxes_for(const RgbdFrame& frame);
  /// Real-time mode: every frame goes to the detector (replacing one it has not started); the freshest result.
  std::optional<DetectionResult> submit_asynchronous(const cv::Mat& image, double timestamp);
  /// Deterministic mode: every deterministic_detect_every-th frame goes to the detector; its result is taken
  /// deterministic_detect_lag frames later (waiting for it then) and used until the next one is taken.
  std::optional<DetectionResult> submit_on_schedule(const cv::Mat& image, double timestamp);

  SemanticSettings settings_;
  std::size_t every_, lag_;  // the deterministic schedule, resolved
  MaskResult current_;    // boxes of the frame below (keep, stats unset)
  PersonRegions people_;  // the same boxes, enlarged, with their person depths
  std::optional<std::pair<std::size_t, double>> current_frame_;  // (index, timestamp)
  AsyncDetector async_;
  std::deque<PastGray> history_;  // recent gray images, to propagate boxes from the image they were found in
  std::optional<Detections> given_;  // the caller's boxes for the next frame
  std::size_t frames_seen_ = 0;                   // frames given to the detector's schedule (deterministic)
  std::optional<std::size_t> outstanding_since_;  // frame count of a submitted frame whose result is not taken
  std::optional<DetectionResult> taken_;          // the result the schedule took last
};

}  // namespace varslam::semantic
