#pragma once
// Synthetic pose-only and BA problems with known truth, for tests and benchmarks of this module.
#include <vector>

#include "core/camera.hpp"
#include "optim/local_ba.hpp"
#include "optim/reprojection.hpp"

namespace varslam::optim {

struct SyntheticPoseOptions {
  int observations = 500;
  double stereo_fraction = 0.8;   // the rest are monocular (no depth)
  double pixel_noise = 1.0;       // sigma at pyramid level 0 [px]
  double outlier_fraction = 0.0;  // gross outliers: uniform random pixels anywhere in the image
  double rotation_error = 0.03;   // initial guess error [rad]
  double translation_error = 0.1; // initial guess error [m]
  unsigned seed = 1;
};

struct SyntheticPose {
  Eigen::Isometry3d T_true, T_init;
  std::vector<Eigen::Vector3d> points_w;
  std::vector<Observation> obs;
  std::vector<bool> is_outlier;  // ground truth
};

SyntheticPose make_synthetic_pose(const PinholeCamera& cam, const SyntheticPoseOptions& opt);

struct SyntheticBaOptions {
  int keyframes = 6;
  int fixed_keyframes = 2;        // the first ones; they keep their true pose in the initial state
  int points = 300;
  double observe_probability = 1.0;  // per visible (keyframe, point) pair
  double stereo_fraction = 0.8;
  double pixel_noise = 1.0;
  double rotation_error = 0.01;     // initial perturbation of the free keyframes [rad]
  double translation_error = 0.05;  // [m]
  double point_error = 0.05;        // initial perturbation of the points [m], per axis sigma
  unsigned seed = 1;
};

struct SyntheticBa {
  BaProblem truth;    // true poses and points (with the noisy observations)
  BaProblem initial;  // perturbed poses and points, same observations
};

SyntheticBa make_synthetic_ba(const PinholeCamera& cam, const SyntheticBaOptions& opt);

/// Root mean square distance between the points of two problems, and mean pose error (translation [m] and
/// rotation [rad]) over the keyframes.
double point_rmse(const BaProblem& a, const BaProblem& b);
double mean_translation_error(const BaProblem& a, const BaProblem& b);
double mean_rotation_error(const BaProblem& a, const BaProblem& b);

}  // namespace varslam::optim
