#include "semantic/detector_settings.hpp"

#include <fmt/format.h>

#include "core/error.hpp"

namespace varslam::semantic {
namespace {
namespace fs = std::filesystem;

// Reads its own keys straight from the YAML tree, so the module depends on the Settings struct only.
class Section {
 public:
  explicit Section(const Settings& s) : file_(s.source.empty() ? std::string("<default settings>") : s.source.string()) {
    if (s.root && s.root.IsMap() && s.root["semantic"]) {
      node_ = s.root["semantic"];
      has_ = !node_.IsNull();  // "semantic:" with nothing under it means defaults
      if (has_ && !node_.IsMap()) throw ConfigError(fmt::format("{}: key 'semantic' must be a map", file_));
    }
    base_ = s.source.empty() ? fs::path() : s.source.parent_path();
  }

  template <typename T>
  void read(const char* key, T& value) const {
    if (!has_ || !node_[key]) return;
    try {
      value = node_[key].as<T>();
    } catch (const YAML::Exception&) {
      throw ConfigError(fmt::format("{}: key 'semantic.{}' has a wrong type", file_, key));
    }
  }

  // Relative paths are relative to the settings file, if that makes them exist; else kept for the model search.
  void read_path(const char* key, fs::path& value) const {
    std::string text;
    read(key, text);
    if (text.empty()) return;
    fs::path p(text);
    std::error_code ec;
    if (p.is_relative() && !base_.empty() && fs::exists(base_ / p, ec)) p = base_ / p;
    value = p;
  }

  void check(bool ok, const char* key, const char* what) const {
    if (!ok) throw ConfigError(fmt::format("{}: key 'semantic.{}' {}", file_, key, what));
  }

 private:
  std::string file_;
  YAML::Node node_;
  bool has_ = false;
  fs::path base_;
};

}  // namespace

SemanticSettings semantic_settings(const Settings& s) {
  const Section sec(s);
  SemanticSettings out;
  DetectorConfig& d = out.detector;
  sec.read("detector", d.source);
  sec.check(d.source == "yolo" || d.source == "boxes" || d.source == "hog" || d.source == "none", "detector",
            "must be one of yolo, boxes, hog, none");
  sec.read("model", d.model);
  sec.read_path("model_dir", d.model_dir);
  sec.read_path("model_cfg", d.model_cfg);
  sec.read_path("model_weights", d.model_weights);
  sec.read_path("names_file", d.names_file);
  sec.read("input_size", d.input_size);
  sec.check(d.input_size > 0 && d.input_size % 32 == 0, "input_size", "must be a positive multiple of 32");
  sec.read("conf_threshold", d.conf_threshold);
  sec.read("nms_threshold", d.nms_threshold);
  sec.check(d.conf_threshold >= 0 && d.conf_threshold <= 1, "conf_threshold", "must be in [0, 1]");
  sec.check(d.nms_threshold > 0 && d.nms_threshold <= 1, "nms_threshold", "must be in (0, 1]");
  sec.read("classes", d.classes);
  sec.read("label_aliases", d.label_aliases);
  sec.read("num_threads", d.num_threads);
  sec.read_path("boxes_file", d.boxes_file);
  sec.read("boxes_max_dt", d.boxes_max_dt);

  FilterConfig& f = out.filter;
  sec.read("box_enlarge", f.box_enlarge);
  sec.check(f.box_enlarge >= 0 && f.box_enlarge < 2, "box_enlarge", "must be in [0, 2)");
  sec.read("depth_band_m", f.depth_band_m);
  sec.check(f.depth_band_m > 0, "depth_band_m", "must be > 0");
  sec.read("min_depth_m", f.min_depth_m);
  sec.read("max_depth_m", f.max_depth_m);
  sec.check(f.max_depth_m > f.min_depth_m, "max_depth_m", "must be larger than min_depth_m");
  sec.read("bin_m", f.bin_m);
  sec.check(f.bin_m > 0, "bin_m", "must be > 0");
  sec.read("peak_fraction", f.peak_fraction);
  sec.read("sample_step", f.sample_step);
  sec.read("silhouette_margin_px", f.silhouette_margin_px);
  sec.check(f.silhouette_margin_px >= 0, "silhouette_margin_px", "must be >= 0");
  sec.read("min_exclusive_share", f.min_exclusive_share);
  sec.check(f.min_exclusive_share >= 0 && f.min_exclusive_share <= 1, "min_exclusive_share", "must be in [0, 1]");

  sec.read("asynchronous", out.asynchronous);
  sec.read("propagate_boxes", out.propagate_boxes);
  sec.read("mask_extraction", out.mask_extraction);
  return out;
}

}  // namespace varslam::semantic
