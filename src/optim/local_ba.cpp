#include "optim/local_ba.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>

#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

namespace varslam::optim {
namespace {

/// The problem's state as Ceres parameter blocks, plus one cost per observation (built once, reused by every
/// solve; Ceres never owns them).
class BaState {
 public:
  BaState(const PinholeCamera& cam, const BaProblem& p, const KernelConfig& kernel, double alpha)
      : cam_(cam), problem_(p), mono_loss_(make_loss(kernel, 2, alpha)), stereo_loss_(make_loss(kernel, 3, alpha)) {
    poses_.resize(p.keyframes.size() * kPoseParams);
    for (std::size_t k = 0; k < p.keyframes.size(); ++k) pose_to_params(p.keyframes[k].T_cw, pose(static_cast<int>(k)));
    points_.resize(p.points.size() * 3);
    for (std::size_t i = 0; i < p.points.size(); ++i) Eigen::Map<Eigen::Vector3d>(point(static_cast<int>(i))) = p.points[i];
    costs_.reserve(p.observations.size());
    for (const BaObservation& o : p.observations) {
      if (o.keyframe < 0 || o.keyframe >= static_cast<int>(p.keyframes.size()) || o.point < 0 ||
          o.point >= static_cast<int>(p.points.size()))
        throw std::invalid_argument("solve_local_ba: observation of keyframe " + std::to_string(o.keyframe) +
                                    ", point " + std::to_string(o.point) + " is out of range");
      if (o.obs.stereo())
        costs_.emplace_back(new ReprojectionCost<3>(cam, o.obs));
      else
        costs_.emplace_back(new ReprojectionCost<2>(cam, o.obs));
    }
  }

  double* pose(int k) { return poses_.data() + static_cast<std::size_t>(k) * kPoseParams; }
  double* point(int i) { return points_.data() + static_cast<std::size_t>(i) * 3; }

  void set_alpha(double alpha) {
    if (mono_loss_) mono_loss_->set_alpha(alpha);
    if (stereo_loss_) stereo_loss_->set_alpha(alpha);
  }

  /// Whitened residual of observation j at the current state; returns its dof, sets depth to z in the camera.
  int residual(std::size_t j, double e[3], double* depth) {
    const BaObservation& o = problem_.observations[j];
    const Eigen::Isometry3d T = params_to_pose(pose(o.keyframe));
    const Eigen::Vector3d p_c = T * Eigen::Map<const Eigen::Vector3d>(point(o.point));
    *depth = p_c.z();
    return whitened_residual(cam_, o.obs, p_c, e, nullptr);
  }

  /// Builds the Ceres problem over the active observations once; later phases only remove observations
  /// (deactivate), so the problem, the residual blocks and the elimination ordering are never rebuilt.
  void build(const std::vector<bool>& active) {
    ceres::Problem::Options po;
    po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // the KernelLoss objects outlive every solve
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.enable_fast_removal = true;
    ceres_ = std::make_unique<ceres::Problem>(po);
    ordering_ = std::make_shared<ceres::ParameterBlockOrdering>();
    blocks_.assign(costs_.size(), nullptr);
    pose_uses_.assign(problem_.keyframes.size(), 0);
    point_uses_.assign(problem_.points.size(), 0);
    for (std::size_t j = 0; j < costs_.size(); ++j) {
      if (!active[j]) continue;
      const BaObservation& o = problem_.observations[j];
      double* x_pose = pose(o.keyframe);
      double* x_point = point(o.point);
      if (pose_uses_[o.keyframe]++ == 0) {
        ceres_->AddParameterBlock(x_pose, kPoseParams, &manifold_);
        if (problem_.keyframes[o.keyframe].fixed) ceres_->SetParameterBlockConstant(x_pose);
        ordering_->AddElementToGroup(x_pose, 1);
      }
      if (point_uses_[o.point]++ == 0) {
        ceres_->AddParameterBlock(x_point, 3);
        ordering_->AddElementToGroup(x_point, 0);  // eliminated first by the Schur complement
      }
      blocks_[j] = ceres_->AddResidualBlock(costs_[j].get(), o.obs.stereo() ? stereo_loss_.get() : mono_loss_.get(),
                                            x_pose, x_point);
    }
  }

  /// Removes observation j from the problem; parameter blocks left without observations leave it too
  /// (and the ordering, which must name exactly the problem's blocks).
  void deactivate(std::size_t j) {
    if (!blocks_[j]) return;
    ceres_->RemoveResidualBlock(blocks_[j]);
    blocks_[j] = nullptr;
    const BaObservation& o = problem_.observations[j];
    if (--pose_uses_[o.keyframe] == 0) {
      ceres_->RemoveParameterBlock(pose(o.keyframe));
      ordering_->Remove(pose(o.keyframe));
    }
    if (--point_uses_[o.point] == 0) {
      ceres_->RemoveParameterBlock(point(o.point));
      ordering_->Remove(point(o.point));
    }
  }

  ceres::Problem& ceres_problem() { return *ceres_; }
  const std::shared_ptr<ceres::ParameterBlockOrdering>& ordering() const { return ordering_; }

  void write_back(BaProblem& p) {
    for (std::size_t k = 0; k < p.keyframes.size(); ++k)
      if (!p.keyframes[k].fixed) p.keyframes[k].T_cw = params_to_pose(pose(static_cast<int>(k)));
    for (std::size_t i = 0; i < p.points.size(); ++i) p.points[i] = Eigen::Map<const Eigen::Vector3d>(point(static_cast<int>(i)));
  }

 private:
  PinholeCamera cam_;
  const BaProblem& problem_;
  std::unique_ptr<KernelLoss> mono_loss_, stereo_loss_;
  std::vector<double> poses_, points_;
  std::vector<std::unique_ptr<ceres::CostFunction>> costs_;
  PoseManifold manifold_;
  std::unique_ptr<ceres::Problem> ceres_;  // declared after the costs, losses and manifold it points to
  std::shared_ptr<ceres::ParameterBlockOrdering> ordering_;
  std::vector<ceres::ResidualBlockId> blocks_;  // per observation; nullptr = not in the problem
  std::vector<int> pose_uses_, point_uses_;     // active observations per parameter block
};

}  // namespace

BaResult solve_local_ba(const PinholeCamera& cam, BaProblem& problem, const BaConfig& cfg) {
  const auto start = std::chrono::steady_clock::now();
  const KernelConfig& kernel = cfg.kernel;
  const bool adaptive = kernel.type == KernelType::BarronAdaptive;
  double alpha = initial_alpha(kernel);
  BaState state(cam, problem, kernel, alpha);
  const std::size_t n = problem.observations.size();
  BaResult result;

  double e[3], depth;
  std::vector<double> initial_sq(n);
  for (std::size_t j = 0; j < n; ++j) {
    const int dof = state.residual(j, e, &depth);
    initial_sq[j] = Eigen::Map<const Eigen::VectorXd>(e, dof).squaredNorm();
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  options.num_threads = std::max(1, cfg.max_threads);
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;

  AlphaSamples samples(kernel.fit);
  auto refit_alpha = [&](const std::vector<bool>& active) {
    samples.clear();
    for (std::size_t j = 0; j < n; ++j) {
      if (!active[j]) continue;
      const int dof = state.residual(j, e, &depth);
      samples.add({e, static_cast<std::size_t>(dof)});
    }
    alpha = fit_alpha(kernel, samples.samples(), alpha);
    result.alpha_per_iteration.push_back(alpha);
    state.set_alpha(alpha);
  };
  // Re-solving a converged problem with an unchanged alpha is a no-op: skip it (saves Ceres' preprocessing
  // when the alternation has settled).
  bool converged = false;
  double solved_alpha = alpha;
  auto solve = [&](ceres::Problem& ceres_problem, int iterations) {
    if (iterations <= 0 || ceres_problem.NumResidualBlocks() == 0) return;
    if (converged && alpha == solved_alpha) return;
    options.max_num_iterations = iterations;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &ceres_problem, &summary);
    result.solver_iterations += static_cast<int>(summary.iterations.size()) - 1;
    converged = summary.termination_type == ceres::CONVERGENCE;
    solved_alpha = alpha;
  };

  // Phase 1: every observation; adaptive alpha alternates with short solves on the same problem (the losses
  // are re-evaluated by every solver iteration, so changing their alpha between solves is all it takes).
  std::vector<bool> active(n, true);
  state.build(active);
  options.linear_solver_ordering = state.ordering();
  if (adaptive) {
    for (int outer = 0; outer < cfg.outer_iterations; ++outer) {
      if (outer > 0 || cfg.alpha_start != AlphaStart::SolveFirst) {
        refit_alpha(active);
      } else {
        result.alpha_per_iteration.push_back(alpha);  // AlphaStart::SolveFirst: barron_alpha, no fit yet
      }
      solve(state.ceres_problem(), cfg.iterations);
    }
  } else {
    solve(state.ceres_problem(), cfg.outer_iterations * cfg.iterations);
  }

  // Outlier gate on the state after phase 1.
  auto gate = [&](std::vector<bool>& outlier) {
    outlier.assign(n, false);
    for (std::size_t j = 0; j < n; ++j) {
      const int dof = state.residual(j, e, &depth);
      const double chi2 = Eigen::Map<const Eigen::VectorXd>(e, dof).squaredNorm();
      outlier[j] = depth <= 0.0 || (kernel.chi2_gates && chi2 > chi2_threshold(dof));
    }
  };
  if (cfg.remove_outliers) {
    std::vector<bool> outlier;
    gate(outlier);
    for (std::size_t j = 0; j < n; ++j) {
      if (!outlier[j]) continue;
      active[j] = false;
      state.deactivate(j);
      converged = false;  // the set of observations changed
    }
  }

  // Phase 2: refine on the surviving observations (same problem, outliers removed).
  if (cfg.refine_iterations > 0) {
    if (adaptive) refit_alpha(active);
    solve(state.ceres_problem(), cfg.refine_iterations);
  }

  state.write_back(problem);
  gate(result.outlier_observation);
  for (std::size_t j = 0; j < n; ++j) {
    if (result.outlier_observation[j]) continue;
    const int dof = state.residual(j, e, &depth);
    result.initial_cost += 0.5 * initial_sq[j];
    result.final_cost += 0.5 * Eigen::Map<const Eigen::VectorXd>(e, dof).squaredNorm();
  }
  result.final_alpha = alpha;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace varslam::optim
