#pragma once
// Large movers close to the camera: a box carried 0.6-1.5 m in front of the lens, covering a quarter to two thirds
// of the image. Each episode enters from one side, may be held still (static in the world), is carried along
// with the camera (swaying like a box in someone's hands), may be held still again, and leaves to a side, slowly
// or fast. The box follows a smoothed copy of the camera's position and heading, so it moves with the camera
// without sharing its hand-held shake; while held still it does not move at all.
#include <Eigen/Geometry>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>
#include <vector>

namespace varslam::synth {

struct LargeBoxEpisode {
  double start = 0, length = 0;  // seconds since the sequence start
  double size = 0.8;             // box edge (metres); its height is 0.85 of it
  double distance = 1.0;         // camera to the near face while carried (metres)
  double coverage = 0.4;         // share of the image the size was chosen to cover
  int enter_side = -1, exit_side = 1;  // -1 = left, +1 = right
  double enter_s = 1, hold_in_s = 0, hold_out_s = 0, exit_s = 1;  // phase lengths; carried = the rest
  double sway_m = 0.1;  // lateral sway amplitude while carried
  double lift_m = 0;    // box centre below (+) or above (-) the camera's height
  // World pose samples every kTrackStep seconds from start: position and yaw (about the vertical axis).
  std::vector<Eigen::Vector4d> track;
  static constexpr double kTrackStep = 0.01;

  bool active(double t) const { return t >= start && t <= start + length; }
  /// Pose of the box centre at t (inside the episode).
  Eigen::Isometry3d pose_at(double t) const;
  nlohmann::json describe() const;
};

/// Plans the episodes of a `duration`-second sequence (two in 20 s, one in a sequence shorter than 12 s) along
/// the camera path pose_at (camera-to-world; y down, z forward), drawing every parameter from rng.
std::vector<LargeBoxEpisode> plan_large_box_episodes(double duration,
                                                     const std::function<Eigen::Isometry3d(double)>& pose_at,
                                                     std::mt19937_64& rng);

}  // namespace varslam::synth
