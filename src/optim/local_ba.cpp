#include "optim/local_ba.hpp"

#include <algorithm>
#include <chrono>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include <ceres/iteration_callback.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "optim/schur_lm.hpp"

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

  /// The dedicated solver on this state (BaSolver::Schur); built on first use.
  SchurLm& schur() {
    if (!schur_) {
      std::vector<bool> fixed;
      for (const BaKeyframe& k : problem_.keyframes) fixed.push_back(k.fixed);
      schur_ = std::make_unique<SchurLm>(cam_, problem_.observations, std::move(fixed), poses_.data(), points_.data(),
                                         problem_.points.size());
    }
    return *schur_;
  }
  const ceres::LossFunction* mono_loss() const { return mono_loss_.get(); }
  const ceres::LossFunction* stereo_loss() const { return stereo_loss_.get(); }
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
    if (blocks_.empty() || !blocks_[j]) return;  // not built: the dedicated solver reads the active flags itself
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
  std::unique_ptr<SchurLm> schur_;
};

/// The alternation's alpha refits as checkpoints inside a Ceres solve (BarronAdaptive). Checkpoint k sits at
/// phase-1 iteration k * `every`, as in the fixed schedule "fit, solve `every` iterations"; a refit that leaves
/// alpha unchanged lets the solve go on, so only a moved alpha pays for a new solve (Ceres' preprocessing and
/// a fresh trust region). Needs Solver::Options::update_state_every_iteration (the refit reads the state).
class AlphaCheckpoints final : public ceres::IterationCallback {
 public:
  /// `refit` fits alpha on the current state, logs and applies it, and says whether alpha changed.
  AlphaCheckpoints(int every, int count, std::function<bool()> refit)
      : every_(every), count_(count), refit_(std::move(refit)) {}

  /// Before each solve: phase-1 iterations already run, on the fixed schedule's clock.
  void start_solve(int iterations_before) {
    offset_ = iterations_before;
    alpha_moved_ = false;
  }
  /// Takes the next checkpoint now (the solve stopped before reaching it); its iteration on the clock.
  int take_next() {
    alpha_moved_ = refit_();
    return every_ * reached_++;
  }
  int reached() const { return reached_; }
  bool alpha_moved() const { return alpha_moved_; }  // the last solve stopped because a refit moved alpha

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (s.iteration == 0 || reached_ >= count_ || offset_ + s.iteration != every_ * reached_)
      return ceres::SOLVER_CONTINUE;
    take_next();
    return alpha_moved_ ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  int every_, count_;
  std::function<bool()> refit_;
  int reached_ = 1;  // checkpoint 0 precedes the first solve
  int offset_ = 0;
  bool alpha_moved_ = false;
};

}  // namespace

BaResult solve_local_ba(const PinholeCamera& cam, BaProblem& problem, const BaConfig& cfg) {
  if (cfg.observer) cfg.observer(cam, problem, cfg);
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
    const FittedAlpha fit = fit_alpha(kernel, samples.samples(), alpha);
    alpha = fit.applied;
    result.alpha_per_iteration.push_back(alpha);
    result.fitted_alpha_per_iteration.push_back(fit.fitted);
    state.set_alpha(alpha);
  };
  // Re-solving a converged problem with an unchanged alpha is a no-op: skip it (saves Ceres' preprocessing
  // when the alternation has settled).
  bool converged = false;
  double solved_alpha = alpha;
  const bool dedicated = cfg.solver == BaSolver::Schur;
  std::vector<bool> active(n, true);
  const auto stop_requested = [&] {
    if (!cfg.stop || !cfg.stop->load()) return false;
    result.cut_short = true;
    return true;
  };
  // Ends a Ceres solve when the caller asks (the dedicated solver checks through its own callback).
  struct StopCallback final : ceres::IterationCallback {
    std::function<bool()> requested;
    ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
      return requested() ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
    }
  } stop_callback;
  stop_callback.requested = stop_requested;
  auto solve = [&](int iterations) {
    if (iterations <= 0 || std::none_of(active.begin(), active.end(), [](bool a) { return a; })) return 0;
    if (stop_requested()) return 0;
    if (converged && alpha == solved_alpha) return 0;
    solved_alpha = alpha;  // before the solve: a checkpoint inside it may change alpha
    if (dedicated) {
      const SchurLmSummary s = state.schur().solve(
          active, state.mono_loss(), state.stereo_loss(), iterations, [&](int iteration) {
            if (stop_requested()) return false;
            ceres::IterationSummary is;
            is.iteration = iteration;
            for (ceres::IterationCallback* cb : options.callbacks)
              if ((*cb)(is) != ceres::SOLVER_CONTINUE) return false;
            return true;
          });
      result.solver_iterations += s.iterations;
      ++result.solves;
      converged = s.converged;
      return s.iterations;
    }
    options.max_num_iterations = iterations;
    if (cfg.stop) options.callbacks.insert(options.callbacks.begin(), &stop_callback);
    ceres::Solver::Summary summary;
    ceres::Solve(options, &state.ceres_problem(), &summary);
    if (cfg.stop) options.callbacks.erase(options.callbacks.begin());
    const int ran = static_cast<int>(summary.iterations.size()) - 1;
    result.solver_iterations += ran;
    ++result.solves;
    converged = summary.termination_type == ceres::CONVERGENCE;
    return ran;
  };

  // Phase 1: every observation; adaptive alpha alternates with the solver on the same problem (the losses are
  // re-evaluated by every solver iteration, so changing their alpha between solves is all it takes).
  if (!dedicated) {
    state.build(active);
    options.linear_solver_ordering = state.ordering();
  }
  if (adaptive) {
    if (cfg.alpha_start != AlphaStart::SolveFirst) {
      refit_alpha(active);
    } else {  // barron_alpha, no fit yet; it stands as its own fit so that both lists stay parallel
      result.alpha_per_iteration.push_back(alpha);
      result.fitted_alpha_per_iteration.push_back(alpha);
    }
    AlphaCheckpoints checkpoints(cfg.iterations, cfg.outer_iterations, [&] {
      const double before = alpha;
      refit_alpha(active);
      return alpha != before;
    });
    options.callbacks = {&checkpoints};
    options.update_state_every_iteration = true;
    const int budget = cfg.outer_iterations * cfg.iterations;
    int clock = 0;  // phase-1 iterations on the fixed schedule's clock
    while (clock < budget && !result.cut_short) {
      checkpoints.start_solve(clock);
      clock += solve(budget - clock);
      if (checkpoints.alpha_moved()) continue;                 // go on with the new alpha
      if (checkpoints.reached() >= cfg.outer_iterations) break;  // Ceres stopped after the last checkpoint
      clock = checkpoints.take_next();  // Ceres stopped early: refit on its final state, as the fixed schedule
    }
    options.callbacks.clear();
    options.update_state_every_iteration = false;
  } else {
    solve(cfg.outer_iterations * cfg.iterations);
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
  if (cfg.refine_iterations > 0 && !result.cut_short) {
    if (adaptive) refit_alpha(active);
    solve(cfg.refine_iterations);
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

KeyframeObservationCounts count_keyframe_observations(const BaProblem& problem,
                                                      const std::vector<bool>& outlier_observation) {
  const std::size_t n = problem.keyframes.size();
  KeyframeObservationCounts c{std::vector<int>(n), std::vector<int>(n), std::vector<int>(n), std::vector<int>(n)};
  std::vector<int> observers(problem.points.size(), 0);
  for (const BaObservation& o : problem.observations) ++observers[static_cast<std::size_t>(o.point)];
  for (std::size_t o = 0; o < problem.observations.size(); ++o) {
    const auto k = static_cast<std::size_t>(problem.observations[o].keyframe);
    const bool shared = observers[static_cast<std::size_t>(problem.observations[o].point)] > 1;
    ++c.total[k];
    c.shared_total[k] += shared;
    if (!outlier_observation[o]) continue;
    ++c.flagged[k];
    c.shared_flagged[k] += shared;
  }
  return c;
}

std::vector<int> keep_diverged_keyframes(BaProblem& problem, const std::vector<Eigen::Isometry3d>& before,
                                         std::vector<bool>& outlier_observation) {
  const KeyframeObservationCounts counts = count_keyframe_observations(problem, outlier_observation);
  std::vector<int> reset;
  for (std::size_t i = 0; i < problem.keyframes.size(); ++i) {
    if (problem.keyframes[i].fixed) continue;
    if (2 * counts.flagged[i] <= counts.total[i] && 2 * counts.shared_flagged[i] <= counts.shared_total[i]) continue;
    problem.keyframes[i].T_cw = before[i];
    reset.push_back(static_cast<int>(i));
  }
  for (std::size_t o = 0; o < problem.observations.size(); ++o)
    if (std::find(reset.begin(), reset.end(), problem.observations[o].keyframe) != reset.end())
      outlier_observation[o] = false;
  return reset;
}

}  // namespace varslam::optim
