#pragma once
// What the generator renders, without rendering it: the static room, the scenario's movers and the camera poses.
// The dense-map benchmark reads the static geometry and the movers' volumes from here (the same (config) gives the
// same world the images were rendered from).
#include <Eigen/Geometry>
#include <functional>
#include <string>
#include <vector>

#include "synth/movers.hpp"
#include "synth/scene.hpp"
#include "synth/synth.hpp"

namespace varslam::synth {

struct World {
  Scene scene;
  Movers movers;
  std::vector<Eigen::Isometry3d> poses;  // camera-to-world per frame (ground truth)
  std::vector<double> stamps;            // per frame
  std::function<Eigen::Isometry3d(double)> pose_at;  // at t seconds since the first frame
  Eigen::Vector3d room_lo = Eigen::Vector3d::Zero(), room_hi = Eigen::Vector3d::Zero();
  double first_timestamp = 0, path_length_s = 0;
  std::string path_source;
};

/// The world of `cfg` (throws InputError for a bad configuration or path, as generate()).
World build_world(const SynthConfig& cfg);

}  // namespace varslam::synth
