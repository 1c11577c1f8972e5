#pragma once
// Runs the SLAM system over a dataset and writes what a user opens afterwards: TUM trajectories, the map
// as PLY, a metrics JSON (and, when ground truth exists, the ATE with its plots).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "io/dataset.hpp"
#include "io/settings.hpp"
#include "slam/config.hpp"
#include "slam/system.hpp"

namespace varslam::slam {

struct RunOptions {
  RunMode mode = RunMode::Deterministic;
  bool pace = false;           // real-time mode: feed frames at the dataset's frame rate (else as fast as possible)
  std::size_t first = 0;       // first frame index
  std::size_t max_frames = SIZE_MAX;
  bool progress = true;        // progress lines on stderr
  std::optional<std::filesystem::path> groundtruth;  // overrides the dataset's groundtruth.txt
  std::set<std::size_t> debug_frames;  // frame indices for which the semantic filter's stages are drawn
};

struct RunSummary {
  std::size_t frames = 0, tracked = 0, lost = 0, keyframes = 0, map_points = 0;
  int segments = 0;
  double wall_seconds = 0, fps = 0;
  std::optional<double> ate_rmse, ate_max;
  nlohmann::json metrics;
  std::filesystem::path out_dir;
};

/// Runs SLAM; the `semantic:` section of the settings decides whether a detector filters known movers
/// (in deterministic mode detection is waited for, so results do not depend on timing).
RunSummary run_slam(const Dataset& dataset, const Settings& settings, const SlamConfig& cfg,
                    const RunOptions& options, const std::filesystem::path& out_dir);

/// Writes the map's points as an ASCII PLY (x y z, with a colour per point).
void write_map_ply(const Map& map, const std::filesystem::path& file);

/// Median and 95th percentile (nearest rank) of a sample, {0, 0} when empty.
std::pair<double, double> median_p95(std::vector<double> v);

}  // namespace varslam::slam
