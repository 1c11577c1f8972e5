#pragma once
// Levenberg-Marquardt for Local BA's fixed structure: 6-dof keyframe poses, 3-dof points, residuals of 2 or 3
// rows each joining one pose and one point. Points are eliminated with the Schur complement on fixed-size blocks
// and the reduced pose system is solved densely (a Local BA window has tens of keyframes and thousands of points,
// so the reduced system is small and the elimination is the work). The step control is Ceres' trust-region LM
// with Jacobi scaling and Ceres' default tolerances, so the solver converges where Ceres' sparse Schur solver did.
#include <functional>
#include <vector>

#include <ceres/loss_function.h>

#include "core/camera.hpp"
#include "optim/local_ba.hpp"
#include "optim/reprojection.hpp"

namespace varslam::optim {

struct SchurLmSummary {
  int iterations = 0;      // as Ceres counts them: every step tried, successful or not
  bool converged = false;  // a tolerance was met (not the iteration budget, not a callback)
};

/// Called after every iteration (1, 2, ...) with the state holding the last accepted step; false stops the solve.
using SchurLmCallback = std::function<bool(int iteration)>;

class SchurLm {
 public:
  /// `poses` (kPoseParams per keyframe, as pose_to_params writes them) and `points` (3 per point) are the state,
  /// updated in place; residuals are whitened_residual's, as ReprojectionCost evaluates them.
  SchurLm(const PinholeCamera& camera, const std::vector<BaObservation>& observations, std::vector<bool> pose_fixed,
          double* poses, double* points, std::size_t points_count);

  /// Up to `max_iterations` iterations on the observations flagged in `active`; `mono_loss` and `stereo_loss`
  /// (nullptr = plain least squares) robustify 2- and 3-row residuals.
  SchurLmSummary solve(const std::vector<bool>& active, const ceres::LossFunction* mono_loss,
                       const ceres::LossFunction* stereo_loss, int max_iterations, const SchurLmCallback& after);

 private:
  struct Linearized;  // per-solve scratch (Jacobians, Hessian blocks, gradient)
  double evaluate(const double* poses, const double* points, Linearized* lin) const;
  bool solve_step(Linearized& lin, double radius, std::vector<double>& step_poses,
                  std::vector<double>& step_points) const;

  PinholeCamera camera_;
  const std::vector<BaObservation>& observations_;
  std::vector<bool> pose_fixed_;
  double* poses_;
  double* points_;
  std::size_t poses_count_, points_count_;
  // Per solve: which observations take part, and which poses and points they make variables.
  const std::vector<bool>* active_ = nullptr;
  const ceres::LossFunction* mono_loss_ = nullptr;
  const ceres::LossFunction* stereo_loss_ = nullptr;
  std::vector<int> pose_var_;                   // keyframe -> variable index, -1 = constant
  std::vector<char> point_used_;                // point has an active observation
  std::vector<std::vector<int>> point_obs_;     // point -> its active observations
  mutable std::vector<Eigen::Matrix3d> rotations_;  // evaluate's scratch: each pose's rotation, once per pass
  mutable std::vector<Eigen::Vector3d> translations_;
};

}  // namespace varslam::optim
