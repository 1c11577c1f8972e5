#include "semantic/dynamic_keypoint_masker.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "semantic/box_propagation.hpp"

namespace varslam::semantic {
namespace {

constexpr std::size_t kHistoryFrames = 10;  // boxes older than this many frames are used unpropagated

cv::Mat gray_of(const RgbdFrame& f) {
  if (!f.gray.empty()) return f.gray;
  cv::Mat g;
  if (f.bgr.channels() == 3) cv::cvtColor(f.bgr, g, cv::COLOR_BGR2GRAY);
  else g = f.bgr;
  return g;
}

}  // namespace

DynamicKeypointMasker::DynamicKeypointMasker(const SemanticSettings& settings)
    : DynamicKeypointMasker(make_detector(settings.detector), settings) {}

DynamicKeypointMasker::DynamicKeypointMasker(std::unique_ptr<Detector> detector, const SemanticSettings& settings)
    : settings_(settings),
      every_(static_cast<std::size_t>(resolved_detect_every(settings))),
      lag_(static_cast<std::size_t>(resolved_detect_lag(settings))),
      async_(std::move(detector)) {}

void DynamicKeypointMasker::boxes_for(const RgbdFrame& frame) {
  const std::pair<std::size_t, double> id{frame.index, frame.timestamp};
  if (current_frame_ == id) return;
  current_frame_ = id;
  const cv::Mat& image = frame.bgr.empty() ? frame.gray : frame.bgr;
  if (given_) {
    MaskResult out;
    out.have_detections = true;
    out.boxes = std::move(*given_);
    given_.reset();
    people_ = locate_people(image.size(), frame.depth, out.boxes, settings_.filter);
    current_ = std::move(out);
    return;
  }
  const std::optional<DetectionResult> latest = settings_.asynchronous ? submit_asynchronous(image, frame.timestamp)
                                                                       : submit_on_schedule(image, frame.timestamp);

  const cv::Mat gray = gray_of(frame);
  if (settings_.propagate_boxes && !gray.empty()) {
    history_.push_back({frame.timestamp, gray});
    if (history_.size() > kHistoryFrames) history_.pop_front();
  }

  MaskResult out;
  if (latest) {
    out.have_detections = true;
    out.boxes = latest->detections;
    out.staleness_s = frame.timestamp - latest->timestamp;
    out.detector_latency_s = latest->latency_s;
    if (settings_.propagate_boxes && !out.boxes.empty() && out.staleness_s > 0.0) {
      for (const auto& past : history_) {
        if (std::abs(past.timestamp - latest->timestamp) < 1e-6) {
          out.boxes = propagate_boxes(out.boxes, past.gray, gray);
          out.propagated = true;
          break;
        }
      }
    }
  }
  people_ = locate_people(image.size(), frame.depth, out.boxes, settings_.filter);
  current_ = std::move(out);
}

std::optional<DetectionResult> DynamicKeypointMasker::submit_asynchronous(const cv::Mat& image, double timestamp) {
  async_.submit(image, timestamp);
  return async_.latest();
}

// Which frames are detected and when their result is taken depend only on the frame count, never on timing: the
// detector's run overlaps the tracking of the next frames and the output stays the same on any machine.
std::optional<DetectionResult> DynamicKeypointMasker::submit_on_schedule(const cv::Mat& image, double timestamp) {
  const auto take_when_due = [this] {
    if (!outstanding_since_ || frames_seen_ - *outstanding_since_ < lag_)
      return;
    async_.wait_idle();
    taken_ = async_.latest();
    outstanding_since_.reset();
  };
  take_when_due();  // before submitting: a new frame must never replace one the schedule still waits for
  if (frames_seen_ % every_ == 0) {
    async_.submit(image, timestamp);
    outstanding_since_ = frames_seen_;
  }
  take_when_due();  // lag 0: this frame's own detections
  ++frames_seen_;
  return taken_;
}

cv::Mat DynamicKeypointMasker::extraction_mask(const RgbdFrame& frame) {
  boxes_for(frame);
  const cv::Mat& image = frame.gray.empty() ? frame.bgr : frame.gray;
  return allowed_pixels(image.size(), frame.depth, people_, settings_.filter);
}

MaskResult DynamicKeypointMasker::process(const RgbdFrame& frame, const std::vector<cv::KeyPoint>& kps) {
  boxes_for(frame);
  MaskResult out = current_;
  out.keep = filter_keypoints(kps, frame.depth, people_, settings_.filter, &out.stats);
  out.people = people_;
  return out;
}

}  // namespace varslam::semantic
