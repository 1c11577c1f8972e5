#pragma once
// Trajectories as TUM text files: "timestamp tx ty tz qx qy qz qw" per line (camera-to-world), '#' comments.
#include <filesystem>

#include "core/trajectory.hpp"

namespace varslam {

/// Reads a TUM trajectory. Throws InputError naming file:line on a malformed line, a non-finite value, a zero
/// quaternion, a timestamp before the previous one, or a repeated timestamp with another pose (more than 1 cm or
/// 1 deg away; the error names both lines). A repeated timestamp with the same pose keeps the later one (as the
/// TUM tools do; real TUM ground truth has a few, 1 mm apart). Quaternions are re-normalised.
Trajectory read_tum_trajectory(const std::filesystem::path& file);

/// How far apart two poses are.
struct PoseGap {
  double metres = 0, degrees = 0;
};
PoseGap pose_gap(const StampedPose& a, const StampedPose& b);

/// Two poses of one timestamp are the same measurement given twice when within 1 cm and 1 deg; farther, one of
/// them is wrong (every reader of ground truth refuses the pair).
bool is_same_measurement(const PoseGap& gap);

/// Writes a TUM trajectory (time with 6 decimals, values with 9 significant digits). Throws InputError if the
/// file cannot be written.
void write_tum_trajectory(const Trajectory& trajectory, const std::filesystem::path& file);

}  // namespace varslam
