#pragma once
// The last check before a final trajectory leaves the system: a pose that no
// frame supports is not written.
#include <Eigen/Geometry>
#include <vector>

#include "core/trajectory.hpp"

namespace varslam::slam {

/// Beyond this, a frame's correction (final pose against the pose tracking gave
/// it) differs from its neighbours' for a reason other than Local BA and loop
/// bends, which move consecutive frames alike: the "dragged" threshold of the
/// benchmarks.
inline constexpr double kIsolatedCorrection = 0.10;  // m

/// `final_poses[i]` and `live_T_wc[i]` are one frame's final and live poses, in
/// frame order. A frame whose final pose moved apart from both neighbours (its
/// correction differs from the previous frame's by more than
/// kIsolatedCorrection while the next frame keeps the previous one's), and
/// whose final pose is off the path between the neighbours by more than twice
/// its live pose is, gets its live pose with the previous frame's correction: a
/// lone keyframe left misplaced by an optimisation (then culled with that pose)
/// must not reach the trajectory, while a frame tracking got wrong and Local BA
/// set right keeps its final pose. Returns how many poses were replaced.
int repair_isolated_poses(Trajectory& final_poses, const std::vector<Eigen::Isometry3d>& live_T_wc);

}  // namespace varslam::slam
