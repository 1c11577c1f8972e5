#pragma once
// A finished run shown the way the live viewer shows a running one (`varslam view --run DIR [--map FILE]`): its
// final and live trajectories, its map (the saved map file when given: keyframes, graph and points; else the run's
// map.ply and keyframe trajectory), ground truth aligned to it, and a slider through the frames whose images come
// from the dataset the run read (when it is still there).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "viewer/viewer_board.hpp"
#include "viewer/viewer_server.hpp"

namespace varslam::viewer {

struct FinishedRun {
  std::string greeting;          // "hello" event: frame stamps and poses for the slider
  std::string map;               // "map" event
  std::vector<std::string> log;  // "alpha" and "loop" events from the run's metrics.json (when there)
  std::size_t frames = 0, map_points = 0, keyframes = 0;
};

/// Reads a run folder (CameraTrajectory.txt needed; LiveTrajectory.txt, KeyFrameTrajectory.txt and map.ply when
/// there). `dataset`: the run's input, for frame stamps and ground truth (null: the trajectory's own stamps).
/// Throws InputError naming the file that is missing or unreadable.
FinishedRun load_finished_run(const std::filesystem::path& run_dir, const Dataset* dataset,
                              const std::optional<std::filesystem::path>& map_file);

/// The images of `dataset`'s frames, as JPEG, by slider position (frame `first + i`).
FrameImageSource dataset_images(const Dataset& dataset, std::size_t first, std::size_t count);

/// The first dataset frame and number of frames the slider covers: those within the trajectory's time span.
std::pair<std::size_t, std::size_t> frames_of_run(const Dataset& dataset, const std::filesystem::path& run_dir);

}  // namespace varslam::viewer
