#pragma once
// Shared by the end-to-end tests: cached synthetic sequences and one call that runs the pipeline on a folder.
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

#include "io/dataset.hpp"
#include "io/settings_registry.hpp"
#include "run/dataset_run.hpp"
#include "synth/synth.hpp"

namespace varslam::slam::e2e {

namespace fs = std::filesystem;

// Generation is the slow part, so sequences are cached per generator version. ctest runs each test in its own
// process, possibly in parallel: generate into a private folder, then rename it into place.
inline fs::path cached_sequence(const std::string& name, synth::SynthConfig cfg) {
  // Not under ctest's per-run temporary folder: the sequences are kept for later runs and the other builds.
#ifdef VARSLAM_TEST_CACHE
  const fs::path cache = VARSLAM_TEST_CACHE;
#else
  const fs::path cache = fs::temp_directory_path();
#endif
  const fs::path d = cache / ("varslam_e2e_" + name + "_g" + std::to_string(synth::kGeneratorVersion));
  if (fs::exists(d / "groundtruth.txt")) return d;
  const fs::path tmp = cache / ("varslam_e2e_tmp_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(tmp);
  cfg.preview = false;
  synth::generate(cfg, tmp);
  std::error_code ec;
  fs::rename(tmp, d, ec);
  if (ec) fs::remove_all(tmp);  // another process won the race: its copy is identical
  return d;
}

/// The 4-s static scene (seed 7) of the end-to-end, sensor-statistics and evaluation tests, with the sensor's depth
/// noise or without.
inline fs::path static_4s_sequence(bool depth_noise = true) {
  synth::SynthConfig cfg;
  cfg.scenario = "static";
  cfg.seconds = 4.0;
  cfg.seed = 7;
  cfg.depth_noise = depth_noise;
  return cached_sequence(depth_noise ? "static_seq" : "static_seq_clean_depth", cfg);
}

/// The 2-s walking scene (seed 5) the pipeline and viewer tests share.
inline fs::path pipeline_walking_sequence() {
  synth::SynthConfig cfg;
  cfg.scenario = "walking";
  cfg.seconds = 2.0;
  cfg.seed = 5;
  return cached_sequence("pipeline_walking", cfg);
}

/// Runs SLAM with the dataset's settings (plus `overrides`, as --set takes them) and these options into `out`.
inline run::RunSummary run_with(const fs::path& data, const fs::path& out, const run::RunOptions& options,
                                const std::vector<std::string>& overrides = {}) {
  Settings settings = settings_for_dataset(data, std::nullopt);
  apply_setting_overrides(settings, overrides);
  auto ds = open_dataset(data, settings);
  return run::run_slam(*ds, settings, options, out);
}

/// The same with the usual options: no progress line, the given mode and frame count.
inline run::RunSummary run_on(const fs::path& data, const fs::path& out, RunMode mode = RunMode::Deterministic,
                         std::size_t max_frames = SIZE_MAX, const std::vector<std::string>& overrides = {}) {
  run::RunOptions ro;
  ro.mode = mode;
  ro.progress = false;
  ro.max_frames = max_frames;
  return run_with(data, out, ro, overrides);
}

}  // namespace varslam::slam::e2e
