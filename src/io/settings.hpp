#pragma once
// Run settings from a YAML file: camera, depth, ORB extractor, plus free-form sections for the stages.
// Accepts our own keys and ORB-SLAM3's camera keys (v1.0 `Camera1.*` and the older `Camera.*` layout).
#include <filesystem>
#include <map>
#include <string>
#include <yaml-cpp/yaml.h>

#include "core/camera.hpp"
#include "core/setting_keys.hpp"

namespace varslam {

struct OrbSettings {
  int n_features = setting_keys::int_default("orb.n_features");
  double scale_factor = setting_keys::real_default("orb.scale_factor");
  int n_levels = setting_keys::int_default("orb.n_levels");
  int ini_th_fast = setting_keys::int_default("orb.ini_th_fast");
  int min_th_fast = setting_keys::int_default("orb.min_th_fast");
  int threads = setting_keys::int_default("orb.threads");
};

struct Settings {
  PinholeCamera camera;
  double fps = setting_keys::real_default("camera.fps");
  double depth_factor = setting_keys::real_default("depth.factor");  // raw depth units per metre
  double th_depth = setting_keys::real_default("depth.th_depth");    // close/far threshold in baselines
  OrbSettings orb;
  YAML::Node root;                 // the whole document, for stage sections (tracking, mapping, robust, ...)
  std::filesystem::path source;    // file it came from; empty for defaults
  std::filesystem::path dataset_dir;  // the dataset these settings run on, when known (relative data files)
  std::map<std::string, std::string> overrides;  // dotted key -> the `--set 'k=v'` that gave it (for messages)

  /// Close/far threshold in metres (ThDepth * baseline).
  double close_depth_m() const { return th_depth * camera.bf / camera.fx; }
};

/// Defaults: TUM fr1-like Kinect camera, 640x480, factor 5000.
Settings default_settings();
/// Parses settings text (`name` names it in errors): refuses text above 1 MiB, invalid YAML and a second YAML
/// document, which would otherwise be ignored.
YAML::Node parse_settings_yaml(const std::string& text, const std::string& name);
/// Load a settings file; throws ConfigError naming the file and key on a missing or malformed value, and on any
/// key the registry (core/setting_keys.hpp) does not declare; naming the file and the reason when it cannot be
/// read (not found, a dangling symbolic link, a folder, no permission).
Settings load_settings(const std::filesystem::path& file);
/// The same from a parsed document (`file` names it in errors, `overrides` the keys set on the command line):
/// re-reads camera, depth and ORB fields after `--set` overrides edited the document. A document that expands
/// (through aliases) to more than 10000 values is refused before it is walked.
Settings settings_from_yaml(const YAML::Node& root, const std::filesystem::path& file,
                            const std::map<std::string, std::string>& overrides = {});
/// Our own YAML layout of `s` (what `synth` puts next to a generated sequence), and writing it to a file.
std::string settings_yaml(const Settings& s);
void save_settings(const Settings& s, const std::filesystem::path& file);

}  // namespace varslam
