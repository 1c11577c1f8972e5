#include "semantic/detector_settings.hpp"

#include <fmt/format.h>

#include <spdlog/spdlog.h>

#include "core/error.hpp"
#include "io/settings_registry.hpp"

namespace varslam::semantic {
namespace {
namespace fs = std::filesystem;

// A relative path is looked up beside the settings file, then as given (from the current folder); `dataset_first`:
// a data file of the dataset (boxes.txt) is looked for in the dataset's folder before both. When none exists, it
// stays as given (the model search and the error messages take it from there), a dataset file in the dataset.
fs::path read_path(const Settings& s, const char* key, bool dataset_first = false) {
  const std::string text = setting<std::string>(s, key);
  if (text.empty()) return {};
  const fs::path p(text);
  if (!p.is_relative()) return p;
  std::error_code ec;
  std::vector<fs::path> candidates;
  if (dataset_first && !s.dataset_dir.empty()) candidates.push_back(s.dataset_dir / p);
  if (!s.source.empty()) candidates.push_back(s.source.parent_path() / p);
  candidates.push_back(p);
  for (const fs::path& c : candidates)
    if (fs::exists(c, ec)) return c;
  return dataset_first && !s.dataset_dir.empty() ? s.dataset_dir / p : p;
}

// `auto`: the paper's system wherever it can be, YOLO when its model files are there, else no person filter.
std::string resolve_detector(const std::string& source, const DetectorConfig& d) {
  if (source != "auto") return source;
  DetectorConfig yolo = d;
  yolo.source = "yolo";
  try {
    resolve_yolo_files(yolo);
    return "yolo";
  } catch (const InputError&) {
    spdlog::info("no person filter: the YOLO model '{}' is not in semantic.model_dir, $VARSLAM_MODELS, ./models or "
                 "<install>/share/varslam/models (README, 'Person detector models', says where to get it); "
                 "semantic.detector: none to run without it quietly",
                 d.model);
    return "none";
  }
}

float real(const Settings& s, const char* key) { return static_cast<float>(setting<double>(s, key)); }

}  // namespace

int resolved_detect_every(const SemanticSettings& s) {
  if (s.deterministic_detect_every > 0) return s.deterministic_detect_every;
  return s.detector.source == "boxes" ? 1 : 2;
}

int resolved_detect_lag(const SemanticSettings& s) {
  return s.deterministic_detect_lag >= 0 ? s.deterministic_detect_lag : resolved_detect_every(s) - 1;
}

SemanticSettings semantic_settings(const Settings& s) {
  SemanticSettings out;
  DetectorConfig& d = out.detector;
  d.model = setting<std::string>(s, "semantic.model");
  d.model_dir = read_path(s, "semantic.model_dir");
  d.model_cfg = read_path(s, "semantic.model_cfg");
  d.model_weights = read_path(s, "semantic.model_weights");
  d.names_file = read_path(s, "semantic.names_file");
  d.source = resolve_detector(setting<std::string>(s, "semantic.detector"), d);
  d.input_size = setting<int>(s, "semantic.input_size");
  if (d.input_size % 32 != 0)
    throw ConfigError(fmt::format("{}: key 'semantic.input_size' must be a multiple of 32, got {}",
                                  s.source.empty() ? std::string("<settings>") : s.source.string(), d.input_size));
  d.conf_threshold = real(s, "semantic.conf_threshold");
  d.nms_threshold = real(s, "semantic.nms_threshold");
  d.classes = setting<std::vector<std::string>>(s, "semantic.classes");
  d.label_aliases = setting<std::map<std::string, std::string>>(s, "semantic.label_aliases");
  d.num_threads = setting<int>(s, "semantic.num_threads");
  d.boxes_file = read_path(s, "semantic.boxes_file", /*dataset_first=*/true);
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
  out.deterministic_detect_every = setting<int>(s, "semantic.deterministic_detect_every");
  out.deterministic_detect_lag = setting<int>(s, "semantic.deterministic_detect_lag");
  if (resolved_detect_lag(out) > resolved_detect_every(out))
    throw ConfigError(fmt::format("{}: key 'semantic.deterministic_detect_lag' ({}) must not exceed the frames between "
                                  "detections (semantic.deterministic_detect_every, here {})",
                                  s.source.empty() ? std::string("<settings>") : s.source.string(),
                                  out.deterministic_detect_lag, resolved_detect_every(out)));
  return out;
}

}  // namespace varslam::semantic
