// OpenCV's built-in HOG + linear SVM pedestrian detector (Dalal-Triggs, 64x128 window): no model file needed.
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

#include "semantic/detector_impl.hpp"

namespace varslam::semantic {
namespace {

class HogDetector final : public Detector {
 public:
  explicit HogDetector(const DetectorConfig& cfg) : label_(kept_label(cfg, "person")), cfg_(cfg) {
    hog_.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector());
  }

  Detections detect(const cv::Mat& bgr, double timestamp) override {
    if (bgr.empty() || label_.empty()) return {};
    std::vector<cv::Rect> rects;
    std::vector<double> weights;
    hog_.detectMultiScale(bgr, rects, weights, /*hitThreshold=*/0.0, cv::Size(8, 8), cv::Size(8, 8), 1.05);
    Detections dets;
    const cv::Rect2f image(0, 0, static_cast<float>(bgr.cols), static_cast<float>(bgr.rows));
    for (std::size_t i = 0; i < rects.size(); ++i) {
      const float score = i < weights.size() ? static_cast<float>(weights[i]) : 1.0f;
      if (score < cfg_.conf_threshold) continue;
      // The 64x128 window has a margin of about 1/8 of its width and 1/16 of its height around the person.
      const cv::Rect2f r(rects[i]);
      const cv::Rect2f tight(r.x + 0.125f * r.width, r.y + 0.0625f * r.height, 0.75f * r.width,
                             0.875f * r.height);
      Detection d;
      d.timestamp = timestamp;
      d.label = label_;
      d.score = score;
      d.box = tight & image;
      if (d.box.area() > 0) dets.push_back(std::move(d));
    }
    return dets;
  }

  std::string name() const override { return "hog"; }

 private:
  std::string label_;  // "person" after aliasing; empty if the class filter excludes people
  DetectorConfig cfg_;
  cv::HOGDescriptor hog_;
};

}  // namespace

std::unique_ptr<Detector> make_hog_detector(const DetectorConfig& cfg) { return std::make_unique<HogDetector>(cfg); }

}  // namespace varslam::semantic
