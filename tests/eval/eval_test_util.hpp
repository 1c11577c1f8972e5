#pragma once
// Helpers shared by the eval tests: constructed trajectories and TUM files.
#include <Eigen/Geometry>
#include <filesystem>
#include <string>

#include "core/trajectory.hpp"
#include "io/trajectory_io.hpp"

namespace varslam::test {

inline Eigen::Isometry3d pose(const Eigen::Vector3d& t, const Eigen::Vector3d& rotvec = Eigen::Vector3d::Zero()) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (rotvec.norm() > 0) T.linear() = Eigen::AngleAxisd(rotvec.norm(), rotvec.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

inline std::filesystem::path shared_trajectories() {
  return std::filesystem::path(VARSLAM_SHARED_DIR) / "trajectories";
}

inline Trajectory read_tum(const std::filesystem::path& p) { return read_tum_trajectory(p); }

}  // namespace varslam::test
