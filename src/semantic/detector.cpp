#include "semantic/detector.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>

#include "core/error.hpp"
#include "semantic/detector_impl.hpp"

namespace varslam::semantic {
namespace fs = std::filesystem;

namespace {

constexpr const char* kNoModelHint =
    "detector sources that need no model file: boxes (a per-frame boxes file), hog (OpenCV's people detector), "
    "none";

class NoDetector final : public Detector {
 public:
  Detections detect(const cv::Mat&, double) override { return {}; }
  std::string name() const override { return "none"; }
};

std::string dirs_text(const std::vector<fs::path>& dirs) {
  if (dirs.empty()) return "no model directory found (VARSLAM_MODELS, ./models, ../shared/models)";
  std::string s = "searched";
  for (const auto& d : dirs) s += " " + d.string();
  return s;
}

// A path as given if it exists (or is absolute), else the first search dir that holds it; the path as given if
// nothing matches, so the error names what the user wrote.
fs::path locate(const fs::path& p, const std::vector<fs::path>& dirs) {
  std::error_code ec;
  if (p.is_absolute() || fs::exists(p, ec)) return p;
  for (const auto& d : dirs)
    if (fs::exists(d / p, ec)) return d / p;
  return p;
}

void require_file(const fs::path& p, const char* what, const std::vector<fs::path>& dirs) {
  std::error_code ec;
  if (!fs::is_regular_file(p, ec))
    throw InputError(fmt::format("yolo detector: {} file '{}' not found ({}); set semantic.model_dir or the env "
                                 "VARSLAM_MODELS, or choose another source; {}",
                                 what, p.string(), dirs_text(dirs), kNoModelHint));
}

std::string preset_names(const std::string& stem) {
  return stem.find("body") != std::string::npos ? "body.names" : "coco.names";
}

}  // namespace

std::vector<fs::path> model_search_dirs(const fs::path& model_dir) {
  std::vector<fs::path> candidates;
  if (!model_dir.empty()) candidates.push_back(model_dir);
  if (const char* env = std::getenv("VARSLAM_MODELS"); env && *env) candidates.emplace_back(env);
  candidates.emplace_back("models");
  candidates.emplace_back("../shared/models");
#ifdef VARSLAM_MODELS_INSTALL_DIR
  candidates.emplace_back(VARSLAM_MODELS_INSTALL_DIR);  // the install prefix's share/varslam/models
#endif
  std::error_code exe_ec;  // and next to an installed program moved elsewhere: <bin>/../share/varslam/models
  const fs::path exe = fs::read_symlink("/proc/self/exe", exe_ec);
  if (!exe_ec) candidates.push_back(exe.parent_path().parent_path() / "share" / "varslam" / "models");
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& c : candidates)
    if (fs::is_directory(c, ec)) out.push_back(c);
  return out;
}

YoloFiles resolve_yolo_files(const DetectorConfig& cfg) {
  const auto dirs = model_search_dirs(cfg.model_dir);
  YoloFiles f;
  if (cfg.model_cfg.empty() && cfg.model_weights.empty()) {
    f.cfg = cfg.model + ".cfg";
    f.weights = cfg.model + ".weights";
  } else {
    f.cfg = cfg.model_cfg;
    f.weights = cfg.model_weights;
  }
  f.weights = locate(f.weights, dirs);
  require_file(f.weights, "weights", dirs);
  const bool onnx = f.weights.extension() == ".onnx";
  if (onnx) {
    f.cfg.clear();
  } else {
    if (f.cfg.empty())
      throw InputError(fmt::format("yolo detector: weights '{}' need a Darknet cfg (semantic.model_cfg); {}",
                                   f.weights.string(), kNoModelHint));
    f.cfg = locate(f.cfg, dirs);
    require_file(f.cfg, "cfg", dirs);
  }
  if (!cfg.names_file.empty()) {
    f.names = locate(cfg.names_file, dirs);
  } else {
    // Next to the weights first (a user's own model), then the preset's class list.
    fs::path beside = f.weights;
    beside.replace_extension(".names");
    std::error_code ec;
    auto search = dirs;
    search.insert(search.begin(), f.weights.parent_path().empty() ? fs::path(".") : f.weights.parent_path());
    f.names = fs::exists(beside, ec) ? beside : locate(preset_names(f.weights.stem().string()), search);
  }
  require_file(f.names, "class names", dirs);
  return f;
}

std::string kept_label(const DetectorConfig& cfg, const std::string& model_label) {
  const auto alias = cfg.label_aliases.find(model_label);
  const std::string& label = alias == cfg.label_aliases.end() ? model_label : alias->second;
  if (cfg.classes.empty() || std::find(cfg.classes.begin(), cfg.classes.end(), label) != cfg.classes.end())
    return label;
  return {};
}

std::unique_ptr<Detector> make_detector(const DetectorConfig& cfg) {
  if (cfg.source == "none" || cfg.source.empty()) return std::make_unique<NoDetector>();
  if (cfg.source == "yolo") return make_yolo_detector(cfg, resolve_yolo_files(cfg));
  if (cfg.source == "hog") return make_hog_detector(cfg);
  if (cfg.source == "boxes") return make_boxes_detector(cfg);
  throw InputError(fmt::format("unknown detector source '{}': expected yolo, boxes, hog or none", cfg.source));
}

}  // namespace varslam::semantic
