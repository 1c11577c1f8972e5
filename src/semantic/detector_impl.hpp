#pragma once
// Internal: constructors of the concrete detectors, used by make_detector() and the tests/benchmarks.
#include <memory>

#include "semantic/detector.hpp"

namespace varslam::semantic {

std::unique_ptr<Detector> make_yolo_detector(const DetectorConfig& cfg, const YoloFiles& files);
std::unique_ptr<Detector> make_hog_detector(const DetectorConfig& cfg);
std::unique_ptr<Detector> make_boxes_detector(const DetectorConfig& cfg);

/// Label after cfg.label_aliases; empty if the aliased label is not in cfg.classes (empty classes keeps all).
std::string kept_label(const DetectorConfig& cfg, const std::string& model_label);

}  // namespace varslam::semantic
