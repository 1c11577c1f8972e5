#pragma once
// Detectors of known movers (people) for the semantic keypoint filter: YOLO through cv::dnn, OpenCV's HOG people
// detector, a per-frame boxes file, or none. make_detector() picks one from a DetectorConfig.
#include <filesystem>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/detection.hpp"
#include "core/setting_keys.hpp"

namespace varslam::semantic {

struct DetectorConfig {
  std::string source = "none";  // yolo | boxes | hog | none (semantic_settings() resolves the setting's auto)
  // yolo: Darknet cfg + weights, or an .onnx file as weights (cfg unused). Empty cfg and weights mean the preset
  // `model` (<model>.cfg + <model>.weights). A relative path that does not exist as given is looked up in
  // model_dir and the default model directories (see model_search_dirs). Empty names_file: <weights stem>.names,
  // else the preset's names (body.names for the body model), else coco.names.
  std::string model{setting_keys::text_default("semantic.model")};  // or "yolo-fastest-1.1-xl"
  std::filesystem::path model_dir;
  std::filesystem::path model_cfg, model_weights, names_file;
  int input_size = setting_keys::int_default("semantic.input_size");
  float conf_threshold = static_cast<float>(setting_keys::real_default("semantic.conf_threshold"));
  float nms_threshold = static_cast<float>(setting_keys::real_default("semantic.nms_threshold"));
  std::vector<std::string> classes = setting_keys::list_default("semantic.classes");  // kept (after aliasing)
  // Model labels renamed before the class filter; the 1-class Yolo-Fastest body model says "body".
  std::map<std::string, std::string> label_aliases = setting_keys::map_default("semantic.label_aliases");
  // yolo: OpenCV worker threads, set when the detector is built. cv::setNumThreads is process wide (TBB
  // backend), so this also applies to the tracker's OpenCV calls; 1 leaves the other core to the tracker, which
  // on a 2-core machine costs the detector little (see bench/semantic_bench.cpp). 0 leaves OpenCV's setting.
  int num_threads = setting_keys::int_default("semantic.num_threads");
  std::filesystem::path boxes_file;  // boxes: per-frame file (src/io/boxes_io.hpp format)
  double boxes_max_dt = setting_keys::real_default("semantic.boxes_max_dt");  // boxes: largest timestamp gap
};

class Detector {
 public:
  virtual ~Detector() = default;
  /// Boxes (pixels of `bgr`) of the configured classes; each Detection carries `timestamp`.
  virtual Detections detect(const cv::Mat& bgr, double timestamp) = 0;
  virtual std::string name() const = 0;
};

/// Builds the configured detector. Throws InputError on an unknown source or a missing model/names/boxes file;
/// the message names the file and lists the sources that need no model (boxes, hog, none).
std::unique_ptr<Detector> make_detector(const DetectorConfig& cfg);

/// Where relative model files are looked up, in order: cfg.model_dir (if set), env VARSLAM_MODELS, ./models,
/// ../shared/models (relative to the current directory), then <install prefix>/share/varslam/models (next to the
/// running program's bin/). Only existing directories are returned.
std::vector<std::filesystem::path> model_search_dirs(const std::filesystem::path& model_dir = {});

/// The YOLO files make_detector() would load: cfg (empty for .onnx), weights, names. Throws InputError (naming
/// the file and the directories searched) when one is missing.
struct YoloFiles {
  std::filesystem::path cfg, weights, names;
};
YoloFiles resolve_yolo_files(const DetectorConfig& cfg);

}  // namespace varslam::semantic
