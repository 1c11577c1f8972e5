#pragma once
// Runs the pipeline over a dataset and writes what a user opens afterwards: TUM trajectories, the map as PLY,
// metrics.json (with the ATE and RPE when ground truth exists). The dataset loop, pacing and the file writers;
// everything SLAM is varslam::Pipeline.
#include <atomic>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <vector>

#include "io/dataset.hpp"
#include "io/settings.hpp"
#include "pipeline/slam.hpp"

namespace varslam::dense {
class DenseMapper;
}

namespace varslam::run {

struct RunOptions {
  RunMode mode = RunMode::Deterministic;
  bool pace = false;           // real-time mode: feed frames at the dataset's frame rate (else as fast as possible)
  bool drop_late = false;      // paced: drop a frame a newer one has overtaken (else track it late and count it)
  std::size_t first = 0;       // first frame index
  std::size_t max_frames = SIZE_MAX;
  bool progress = true;        // progress line on stderr
  std::optional<std::filesystem::path> groundtruth;  // overrides the dataset's groundtruth.txt
  // Frame indices for which the semantic filter's stages are drawn; one outside the run's frames is an InputError.
  std::set<std::size_t> debug_frames;
  std::vector<Observer*> observers;    // more observers of the pipeline (e.g. a live viewer)
  // A run tracking a smaller share of its frames failed (RunSummary::failure says why); 0 accepts any run.
  double min_tracked_share = 0.5;
  const std::atomic<bool>* stop = nullptr;  // set (e.g. by a signal handler) to end the run early, cleanly
  std::optional<std::filesystem::path> load_map;  // start from this saved map
  bool localization_only = false;                 // with load_map: track without extending the map
  // Write the final map here; with ground truth, the final trajectory's alignment goes with it.
  std::optional<std::filesystem::path> save_map;
};

struct RunSummary {
  std::size_t frames = 0, tracked = 0, lost = 0, keyframes = 0, map_points = 0;
  int segments = 0;
  double wall_seconds = 0, fps = 0;
  std::optional<double> ate_rmse, ate_max;
  std::optional<double> ate_map_frame_rmse, ate_map_frame_max;  // a run on a loaded map, in the map's alignment
  std::optional<double> ate_live_rmse, ate_live_max;  // the poses as tracking gave them
  std::size_t dragged_events = 0;  // the live pose jumped > 10 cm against ground truth within 1 s (eval/drag_events)
  std::string ate_note;          // why there is no ATE although ground truth exists
  std::optional<std::string> failure;  // the run tracked too little: the share and the likely cause
  bool interrupted = false;      // stopped through RunOptions::stop; the outputs hold what was tracked
  std::optional<std::string> map_error;  // RunOptions::save_map could not be written (checked before the run too)
  nlohmann::json metrics;
  std::filesystem::path out_dir;
};

/// Runs SLAM with `settings` (the `semantic:` section decides whether a detector filters known movers; in
/// deterministic mode detection is waited for, so results do not depend on timing). Ground truth is read before
/// the run (a broken file fails at once); outputs of an earlier run in `out_dir` (those its .varslam-outputs lists)
/// are removed first, a folder holding files of the user's under the run's output names is refused, every output
/// is written atomically, and a second run into the same folder at the same time is refused (InputError).
RunSummary run_slam(const Dataset& dataset, const Settings& settings, const RunOptions& options,
                    const std::filesystem::path& out_dir);

/// Writes the dense map (dense_mesh.ply, dense_map.bt) into out_dir; returns its metrics.json entry.
nlohmann::json write_dense_map(dense::DenseMapper& dense_map, const std::filesystem::path& out_dir);

/// Writes the map's points as an ASCII PLY (x y z).
void write_map_ply(const slam::Map& map, const std::filesystem::path& file);

}  // namespace varslam::run
