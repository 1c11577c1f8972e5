#include "semantic/detector_settings.hpp"

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/settings_registry.hpp"

namespace varslam::semantic {
namespace {
namespace fs = std::filesystem;

// Relative paths are relative to the settings file, if that makes them exist; else kept for the model search.
fs::path read_path(const Settings& s, const char* key) {
  const std::string text = setting<std::string>(s, key);
  if (text.empty()) return {};
  fs::path p(text);
  std::error_code ec;
  const fs::path base = s.source.empty() ? fs::path() : s.source.parent_path();
  if (p.is_relative() && !base.empty() && fs::exists(base / p, ec)) p = base / p;
  return p;
}

float real(const Settings& s, const char* key) { return static_cast<float>(setting<double>(s, key)); }

}  // namespace

SemanticSettings semantic_settings(const Settings& s) {
  SemanticSettings out;
  DetectorConfig& d = out.detector;
  d.source = setting<std::string>(s, "semantic.detector");
  d.model = setting<std::string>(s, "semantic.model");
  d.model_dir = read_path(s, "semantic.model_dir");
  d.model_cfg = read_path(s, "semantic.model_cfg");
  d.model_weights = read_path(s, "semantic.model_weights");
  d.names_file = read_path(s, "semantic.names_file");
  d.input_size = setting<int>(s, "semantic.input_size");
  if (d.input_size % 32 != 0)
    throw ConfigError(fmt::format("{}: key 'semantic.input_size' must be a multiple of 32, got {}",
                                  s.source.empty() ? std::string("<settings>") : s.source.string(), d.input_size));
  d.conf_threshold = real(s, "semantic.conf_threshold");
  d.nms_threshold = real(s, "semantic.nms_threshold");
  d.classes = setting<std::vector<std::string>>(s, "semantic.classes");
  d.label_aliases = setting<std::map<std::string, std::string>>(s, "semantic.label_aliases");
  d.num_threads = setting<int>(s, "semantic.num_threads");
  d.boxes_file = read_path(s, "semantic.boxes_file");
  d.boxes_max_dt = setting<double>(s, "semantic.boxes_max_dt");

  FilterConfig& f = out.filter;
  f.box_enlarge = real(s, "semantic.box_enlarge");
  f.depth_band_m = real(s, "semantic.depth_band_m");
  f.min_depth_m = real(s, "semantic.min_depth_m");
  f.max_depth_m = real(s, "semantic.max_depth_m");
  if (!(f.max_depth_m > f.min_depth_m))
    throw ConfigError(fmt::format("{}: key 'semantic.max_depth_m' must be larger than semantic.min_depth_m",
                                  s.source.empty() ? std::string("<settings>") : s.source.string()));
  f.bin_m = real(s, "semantic.bin_m");
  f.peak_fraction = real(s, "semantic.peak_fraction");
  f.sample_step = setting<int>(s, "semantic.sample_step");
  f.silhouette_margin_px = real(s, "semantic.silhouette_margin_px");
  f.min_exclusive_share = real(s, "semantic.min_exclusive_share");

  out.asynchronous = setting<bool>(s, "semantic.asynchronous");
  out.propagate_boxes = setting<bool>(s, "semantic.propagate_boxes");
  out.mask_extraction = setting<bool>(s, "semantic.mask_extraction");
  return out;
}

}  // namespace varslam::semantic
