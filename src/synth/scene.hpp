#pragma once
// The static part of a synthetic scene: a closed room around the camera path, furniture, wall decorations,
// their textures and materials, and the lights.
#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "synth/primitives.hpp"
#include "synth/texture.hpp"

namespace varslam::synth {

struct Material {
  int texture = 0;
  double texel_m = 0.005;  // metres per level-0 texel
  std::string name;
};

struct Scene {
  Eigen::Vector3d room_lo = Eigen::Vector3d::Zero(), room_hi = Eigen::Vector3d::Zero();
  int face_material[3][2] = {{0, 0}, {0, 0}, {0, 0}};  // room faces by axis and side (y: 0 ceiling, 1 floor)
  std::vector<Texture> textures;
  std::vector<Material> materials;
  std::vector<Primitive> statics;
  std::vector<Eigen::Vector3d> lights;
  double floor_y = 0.0;  // y grows downward (gravity)

  int add_texture(const cv::Mat& bgr);
  int add_material(int texture, double texel_m, std::string name);
};

/// Where the action happens: the mean camera position and mean (horizontal) viewing direction.
struct ViewAnchor {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // mean camera position
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ();  // unit, horizontal (y = 0)
  Eigen::Vector3d right = Eigen::Vector3d::UnitX();    // unit, horizontal, forward x right = down
};

/// Keep-out zones on the floor (x, z circles) where no furniture may stand: camera path, walking lanes.
struct KeepOut {
  Eigen::Vector2d xz;
  double radius;
};

/// Build room + furniture. room_lo/hi must already enclose path and movers; floor_y is the floor height.
Scene build_static_scene(const Eigen::Vector3d& room_lo, const Eigen::Vector3d& room_hi, const ViewAnchor& anchor,
                         const std::vector<KeepOut>& keep_out, std::uint64_t seed);

}  // namespace varslam::synth
