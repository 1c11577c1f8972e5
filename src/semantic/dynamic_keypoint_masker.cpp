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
    : settings_(settings), async_(std::move(detector)) {}

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
  async_.submit(image, frame.timestamp);
  if (!settings_.asynchronous) async_.wait_idle();

  const cv::Mat gray = gray_of(frame);
  if (settings_.propagate_boxes && !gray.empty()) {
    history_.push_back({frame.timestamp, gray});
    if (history_.size() > kHistoryFrames) history_.pop_front();
  }

  MaskResult out;
  if (const auto latest = async_.latest()) {
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
