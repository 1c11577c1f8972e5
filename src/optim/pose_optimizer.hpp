#pragma once
// Pose-only optimisation for tracking: refine T_cw from fixed world points and their observations, with
// ORB-SLAM's round schedule (optimise, re-classify outliers by chi2, optimise again without them).
#include <functional>
#include <vector>

#include <Eigen/Geometry>

#include "core/camera.hpp"
#include "optim/kernel.hpp"
#include "optim/reprojection.hpp"

namespace varslam::optim {

/// Two solvers of the same problem with the same kernel code, tested against each other. Measured
/// (bench/optim_bench problem, 500 observations, 4 rounds x 10 iterations, callgrind instructions):
/// Dedicated 14.2M Huber / 17.9M Barron(1) (1.26x); Ceres 21.4M / 33.9M (1.59x). Ceres drops the rho''
/// term of robust losses (its corrector applies it only for rho'' > 0), so on smooth kernels it is plain IRLS
/// and needs ~2x Huber's iterations; the dedicated solver switches to the full Gauss-Newton Hessian near
/// the optimum. Ceres stays the default (the previous engineer's choice); Dedicated is ~1.5-2x faster.
enum class PoseSolver {
  Dedicated,  // small 6-DoF Levenberg-Marquardt with IRLS weights
  Ceres,      // ceres::Problem per round, PoseManifold, DENSE_NORMAL_CHOLESKY
};

struct PoseOptimConfig;
/// Sees a problem before optimize_pose solves it (bench/kernel_cost_bench records the tracking problems of a
/// real run to replay them under other kernels). Called from the optimising thread.
using PoseProblemObserver =
    std::function<void(const PinholeCamera&, const Eigen::Isometry3d& T_cw, const std::vector<Eigen::Vector3d>& points_w,
                       const std::vector<Observation>& obs, const PoseOptimConfig& cfg,
                       const std::vector<bool>* initial_outliers)>;

struct PoseOptimConfig {
  KernelConfig kernel;
  int rounds = 4;
  int iterations_per_round = 10;
  PoseSolver solver = PoseSolver::Ceres;
  PoseProblemObserver observer;  // empty: none
};

struct PoseOptimResult {
  int inliers = 0;            // observations passing the chi2 gate at the final pose
  std::vector<bool> outlier;  // per observation, after the last round
  double seconds = 0;
  double alpha = 2.0;         // kernel alpha used in the last round (Barron kernels; 2 otherwise)
  int iterations = 0;         // solver iterations over all rounds (Dedicated: trial steps; Ceres: its iterations)
};

/// Refines T_cw from 3-D world points and their observations; outliers re-classified each round by chi2
/// (mono 5.991, stereo 7.815), outliers excluded from the next round but re-tested (they can come back).
/// Each round continues from the previous round's pose. With kernel.chi2_gates = false no observation is
/// ever excluded (the kernel alone handles outliers); `outlier` still reports the chi2 test.
/// Observations behind the camera always count as outliers. `initial_outliers` (same size as obs) are
/// excluded from the first round only.
PoseOptimResult optimize_pose(const PinholeCamera& cam, Eigen::Isometry3d& T_cw,
                              const std::vector<Eigen::Vector3d>& points_w, const std::vector<Observation>& obs,
                              const PoseOptimConfig& cfg, const std::vector<bool>* initial_outliers = nullptr);

}  // namespace varslam::optim
