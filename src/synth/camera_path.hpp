#pragma once
// Camera paths for the generator: loading (file, folder or the built-in real excerpt), pose interpolation at
// arbitrary times, and re-expression relative to the first pose.
#include <filesystem>
#include <string>

#include "core/trajectory.hpp"

namespace varslam::synth {

/// The compiled-in excerpt of TUM fr2/desk_with_person ground truth (about 20 s at 30 Hz).
Trajectory builtin_camera_path();

/// Path from a TUM groundtruth file or a folder holding groundtruth.txt; empty path = built-in.
/// Throws InputError for a missing/malformed file or fewer than two poses. `source` receives a description.
Trajectory load_camera_path(const std::filesystem::path& path_file, std::string* source = nullptr);

/// Pose at time t: lerp of the translation, slerp of the rotation between the two bracketing poses
/// (clamped at the ends). The trajectory must be sorted by time and non-empty.
Eigen::Isometry3d interpolate_pose(const Trajectory& path, double t);

}  // namespace varslam::synth
