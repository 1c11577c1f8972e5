#pragma once
// CPU ray caster: one primary ray per pixel, primitives culled per 16x16 screen tile by their projected
// bounds, Lambert shading, trilinear texture sampling with the level chosen from the pixel footprint.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

#include "core/camera.hpp"
#include "synth/scene.hpp"

namespace varslam::synth {

struct RenderOutput {
  cv::Mat3f color;  // BGR in [0, 1] (before sensor effects)
  cv::Mat1f depth;  // metres along the optical axis, exact
  cv::Mat1b ids;    // object id per pixel (kStaticId, person ids, object ids)
};

class Renderer {
 public:
  explicit Renderer(const PinholeCamera& cam);
  /// Render the static scene plus the given dynamic primitives seen from camera-to-world pose T_wc.
  void render(const Scene& scene, const std::vector<Primitive>& dynamic, const Eigen::Isometry3d& T_wc,
              RenderOutput& out) const;

 private:
  PinholeCamera cam_;
  std::vector<Eigen::Vector3d> rays_;  // unit ray per pixel in the camera frame
  std::vector<double> z_per_t_;        // optical-axis depth per unit distance along the ray
};

}  // namespace varslam::synth
