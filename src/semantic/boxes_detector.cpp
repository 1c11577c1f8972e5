// "Detector" that replays a per-frame boxes file (precomputed or ground-truth boxes).
#include <fmt/format.h>

#include "core/error.hpp"
#include "io/boxes_io.hpp"
#include "semantic/detector_impl.hpp"

namespace varslam::semantic {
namespace {

class BoxesDetector final : public Detector {
 public:
  explicit BoxesDetector(const DetectorConfig& cfg) : cfg_(cfg) {
    if (cfg.boxes_file.empty())
      throw InputError("boxes detector: no boxes file given (semantic.boxes_file); other sources: yolo, hog, none");
    std::error_code ec;
    if (!std::filesystem::is_regular_file(cfg.boxes_file, ec))
      throw InputError(fmt::format("{}: boxes file not found; other detector sources: yolo, hog, none",
                                   cfg.boxes_file.string()));
    boxes_ = read_boxes_file(cfg.boxes_file);
  }

  Detections detect(const cv::Mat&, double timestamp) override {
    Detections out;
    for (Detection d : boxes_near(boxes_, timestamp, cfg_.boxes_max_dt)) {
      d.label = kept_label(cfg_, d.label);
      if (!d.label.empty()) out.push_back(std::move(d));
    }
    return out;
  }

  std::string name() const override { return "boxes(" + cfg_.boxes_file.filename().string() + ")"; }

 private:
  DetectorConfig cfg_;
  BoxesByTime boxes_;
};

}  // namespace

std::unique_ptr<Detector> make_boxes_detector(const DetectorConfig& cfg) {
  return std::make_unique<BoxesDetector>(cfg);
}

}  // namespace varslam::semantic
