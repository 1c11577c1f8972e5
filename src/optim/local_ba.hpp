#pragma once
// Local Bundle Adjustment for local mapping on plain data: keyframe poses T_cw, world points, observations.
#include <atomic>
#include <functional>
#include <vector>

#include <Eigen/Geometry>

#include "core/camera.hpp"
#include "optim/kernel.hpp"
#include "optim/reprojection.hpp"

namespace varslam::optim {

struct BaKeyframe {
  Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
  bool fixed = false;  // observes the local points but is not optimised (anchors the gauge)
};

struct BaObservation {
  int keyframe = 0;  // index into BaProblem::keyframes
  int point = 0;     // index into BaProblem::points
  Observation obs;
};

struct BaProblem {
  std::vector<BaKeyframe> keyframes;
  std::vector<Eigen::Vector3d> points;
  std::vector<BaObservation> observations;
};

/// BarronAdaptive: what the first outer iteration does.
enum class AlphaStart {
  FitInitialState,  // the paper: fit alpha on the initial state, then solve
  // First solve with kernel.barron_alpha, fits from its result on: cheaper, but the strongly robust first
  // solve is what keeps a mover out (BENCHMARKS.md, "Why the defaults"). Hence not the default.
  SolveFirst,
};

/// Which solver runs the Local BA iterations: the dedicated Schur-complement LM (optim/schur_lm.hpp) or Ceres'
/// general sparse Schur solver, with the same step control; kept to compare the two.
enum class BaSolver { Schur, Ceres };

struct BaConfig;
/// Sees a problem before solve_local_ba solves it (bench/kernel_cost_bench records the Local BA problems of a
/// real run to replay them under other kernels). Called from the solving thread.
using LocalBaObserver = std::function<void(const PinholeCamera&, const BaProblem&, const BaConfig&)>;

struct BaConfig {
  KernelConfig kernel;
  AlphaStart alpha_start = AlphaStart::FitInitialState;
  int outer_iterations = 3;    // first phase: outer_iterations x iterations solver iterations
  int iterations = 5;
  int refine_iterations = 10;  // second phase, after the outlier gate
  bool remove_outliers = true;
  BaSolver solver = BaSolver::Schur;
  int max_threads = 1;  // Ceres only
  // Set by another thread when the solve should end early (real time: a newer keyframe waits). The solve stops
  // after its current iteration, skips what is left, and keeps the state it reached (every accepted step lowered
  // the cost). nullptr: never.
  const std::atomic<bool>* stop = nullptr;
  LocalBaObserver observer;  // empty: none
};

struct BaResult {
  std::vector<bool> outlier_observation;  // at the final state: behind the camera, or failing the chi2 gate
  std::vector<double> alpha_per_iteration;  // BarronAdaptive: the alpha of each solve (fitted before it, except
                                            // the first one with AlphaStart::SolveFirst)
  std::vector<double> fitted_alpha_per_iteration;  // parallel to alpha_per_iteration: the fits before
                                                   // KernelConfig::alpha_max capped them
  double final_alpha = 2;                   // alpha of the last solve (barron_alpha for BarronFixed, 2 otherwise)
  double seconds = 0;
  // 0.5 * sum of squared whitened residuals over the observations that are inliers at the end, at the initial
  // and at the final state (plain least squares, so comparable whatever kernel and alpha were used).
  double initial_cost = 0, final_cost = 0;
  int solver_iterations = 0;  // total over all Ceres solves
  int solves = 0;             // Ceres solves run (each one preprocesses the problem again)
  bool cut_short = false;     // BaConfig::stop ended it before its schedule
};

/// Local BA: optimise non-fixed keyframes and all points in place. ORB-SLAM-style schedule: solve, then mark
/// observations failing the chi2 test (or with non-positive depth) as outliers, solve again without them.
/// Fixed kernels solve the first phase in one go; BarronAdaptive alternates: each outer iteration estimates
/// alpha on the current active whitened residuals (fixed state), then runs `iterations` solver iterations with
/// that alpha; the refine phase fits alpha once more on the surviving observations. The refits are checkpoints
/// inside one solve (every `iterations` iterations): only a refit that moves alpha ends the solve and starts a
/// new one (BaResult::solves). Alpha changes only touch the loss objects, and the refine phase removes the
/// outlier observations. With kernel.chi2_gates = false only observations behind the camera are gated.
/// BaSolver::Schur (default): optim/schur_lm.hpp. BaSolver::Ceres: Ceres SPARSE_SCHUR with points eliminated
/// first and PoseManifold on the poses, its problem built once. Both deterministic (Ceres with max_threads = 1).
/// Throws std::invalid_argument on an observation indexing a missing keyframe or point.
BaResult solve_local_ba(const PinholeCamera& cam, BaProblem& problem, const BaConfig& cfg);

/// Per problem keyframe: how many observations it has and how many of them `outlier_observation` flags.
struct KeyframeObservationCounts {
  std::vector<int> total, flagged;
  // The same over observations of points another keyframe of the problem observes too: a keyframe's private points
  // (seen by it alone) move with it, so only shared points testify for its pose.
  std::vector<int> shared_total, shared_flagged;
};
KeyframeObservationCounts count_keyframe_observations(const BaProblem& problem,
                                                      const std::vector<bool>& outlier_observation);

/// A free keyframe that the solve left with more than half of its observations flagged as outliers has
/// diverged (seen: 220 of 284, moved 1.46 m, in a walking scene), and so has one with more than half of its
/// observations of shared points flagged: a weak keyframe (a motion-blurred frame tracked with few inliers) can
/// carry its many private points away with it while the shared ones are flagged (seen: 163 of 333 flagged, most of
/// them shared, moved 1.74 m). Its pose goes back to `before` (one pose per problem keyframe) and its observations
/// are unflagged. Returns the indices of the keyframes reset.
std::vector<int> keep_diverged_keyframes(BaProblem& problem, const std::vector<Eigen::Isometry3d>& before,
                                         std::vector<bool>& outlier_observation);


}  // namespace varslam::optim
