#pragma once
// Run settings from a YAML file: camera, depth, ORB extractor, plus free-form sections for the stages.
// Accepts our own keys and ORB-SLAM3's camera keys (v1.0 `Camera1.*` and the older `Camera.*` layout).
#include <filesystem>
#include <string>
#include <yaml-cpp/yaml.h>

#include "core/camera.hpp"

namespace varslam {

struct OrbSettings {
  int n_features = 1000;
  double scale_factor = 1.2;
  int n_levels = 8;
  int ini_th_fast = 20;
  int min_th_fast = 7;
};

struct Settings {
  PinholeCamera camera;
  double fps = 30.0;
  double depth_factor = 5000.0;  // raw depth units per metre (TUM/Bonn 5000, OpenLORIS/7-Scenes 1000)
  double th_depth = 40.0;        // close/far threshold in baselines (ORB-SLAM's ThDepth)
  OrbSettings orb;
  YAML::Node root;                 // the whole document, for stage sections (tracking, mapping, robust, ...)
  std::filesystem::path source;    // file it came from; empty for defaults

  /// Close/far threshold in metres (ThDepth * baseline).
  double close_depth_m() const { return th_depth * camera.bf / camera.fx; }
};

/// Defaults: TUM fr1-like Kinect camera, 640x480, factor 5000.
Settings default_settings();
/// Load a settings file; throws ConfigError naming the file and key on a missing or malformed value.
Settings load_settings(const std::filesystem::path& file);
/// The same from a parsed document (`file` names it in errors): re-reads camera, depth and ORB fields after
/// `--set` overrides edited the document.
Settings settings_from_yaml(const YAML::Node& root, const std::filesystem::path& file);
/// Our own YAML layout of `s` (what `synth` puts next to a generated sequence), and writing it to a file.
std::string settings_yaml(const Settings& s);
void save_settings(const Settings& s, const std::filesystem::path& file);

/// Typed read of an optional key inside a section ("tracking.kernel" style dotted path); a wrong type is a
/// ConfigError that names the settings file and the key.
template <typename T>
T setting_or(const Settings& s, const std::string& dotted_key, const T& fallback);

}  // namespace varslam
