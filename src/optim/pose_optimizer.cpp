#include "optim/pose_optimizer.hpp"

#include <chrono>
#include <memory>
#include <stdexcept>

#include <ceres/problem.h>
#include <ceres/solver.h>

#include "core/geometry.hpp"

namespace varslam::optim {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

constexpr int kMinActive = 5;  // below this a 6-DoF pose is not worth optimising

/// Robust cost (and optionally the IRLS normal equations) of the active observations at T.
double linearize(const PinholeCamera& cam, const Eigen::Isometry3d& T, const std::vector<Eigen::Vector3d>& points,
                 const std::vector<Observation>& obs, const std::vector<bool>& active, const KernelConfig& kernel,
                 double alpha, Matrix6d* H, Vector6d* b) {
  double cost = 0;
  if (H) {
    H->setZero();
    b->setZero();
  }
  double e[3], rho[3];
  Eigen::Matrix3d J_pc;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    if (!active[i]) continue;
    const Eigen::Vector3d p_c = T * points[i];
    const int dof = whitened_residual(cam, obs[i], p_c, e, H ? &J_pc : nullptr);
    const Eigen::Map<const Eigen::VectorXd> ev(e, dof);
    evaluate_kernel(kernel, alpha, dof, ev.squaredNorm(), rho);
    cost += rho[0];
    if (!H) continue;
    // First-order IRLS: weight rho'(s) on J^T J (no rho'' term; it can make H indefinite).
    const Eigen::Matrix<double, Eigen::Dynamic, 6, 0, 3, 6> J = J_pc.topRows(dof) * dpc_dpose(p_c);
    H->noalias() += rho[1] * J.transpose() * J;
    b->noalias() += rho[1] * J.transpose() * ev;
  }
  return 0.5 * cost;
}

/// Levenberg-Marquardt on the 6-DoF left update, Marquardt-scaled damping. An iteration is one trial step.
void solve_dedicated(const PinholeCamera& cam, Eigen::Isometry3d& T, const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Observation>& obs, const std::vector<bool>& active, const KernelConfig& kernel,
                     double alpha, int iterations) {
  Matrix6d H;
  Vector6d b;
  double cost = linearize(cam, T, points, obs, active, kernel, alpha, &H, &b);
  double lambda = 1e-4;
  for (int it = 0; it < iterations; ++it) {
    Matrix6d A = H;
    A.diagonal() += lambda * H.diagonal().cwiseMax(1e-9);
    const Vector6d delta = A.ldlt().solve(-b);
    if (!delta.allFinite()) break;
    const Eigen::Isometry3d T_new = se3_left_update(T, delta);
    Matrix6d H_new;
    Vector6d b_new;
    const double cost_new = linearize(cam, T_new, points, obs, active, kernel, alpha, &H_new, &b_new);
    if (cost_new < cost) {
      // Same stopping rule as Ceres' default function_tolerance, so both solvers do comparable work.
      const bool converged = delta.squaredNorm() < 1e-20 || cost - cost_new < 1e-6 * cost;
      T = T_new;
      H = H_new;
      b = b_new;
      cost = cost_new;
      lambda = std::max(lambda * 0.1, 1e-12);
      if (converged) break;
    } else {
      lambda *= 10.0;
      if (lambda > 1e10) break;
    }
  }
  T = normalized(T);
}

/// The same problem on Ceres: kept to measure against (and as a reference in tests).
class CeresPoseSolver {
 public:
  CeresPoseSolver(const PinholeCamera& cam, const std::vector<Eigen::Vector3d>& points,
                  const std::vector<Observation>& obs, const KernelConfig& kernel, double alpha)
      : mono_loss_(make_loss(kernel, 2, alpha)), stereo_loss_(make_loss(kernel, 3, alpha)) {
    costs_.reserve(obs.size());
    for (std::size_t i = 0; i < obs.size(); ++i) {
      if (obs[i].stereo())
        costs_.emplace_back(new PoseOnlyCost<3>(cam, obs[i], points[i]));
      else
        costs_.emplace_back(new PoseOnlyCost<2>(cam, obs[i], points[i]));
    }
    options_.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    options_.num_threads = 1;
    options_.logging_type = ceres::SILENT;
    options_.minimizer_progress_to_stdout = false;
  }

  void solve(Eigen::Isometry3d& T, const std::vector<Observation>& obs, const std::vector<bool>& active,
             double alpha, int iterations) {
    if (mono_loss_) mono_loss_->set_alpha(alpha);
    if (stereo_loss_) stereo_loss_->set_alpha(alpha);
    ceres::Problem::Options po;
    po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(po);
    double x[kPoseParams];
    pose_to_params(T, x);
    problem.AddParameterBlock(x, kPoseParams, &manifold_);
    for (std::size_t i = 0; i < obs.size(); ++i) {
      if (!active[i]) continue;
      problem.AddResidualBlock(costs_[i].get(), obs[i].stereo() ? stereo_loss_.get() : mono_loss_.get(), x);
    }
    options_.max_num_iterations = iterations;
    ceres::Solver::Summary summary;
    ceres::Solve(options_, &problem, &summary);
    T = params_to_pose(x);
  }

 private:
  std::unique_ptr<KernelLoss> mono_loss_, stereo_loss_;
  std::vector<std::unique_ptr<ceres::CostFunction>> costs_;
  PoseManifold manifold_;
  ceres::Solver::Options options_;
};

}  // namespace

PoseOptimResult optimize_pose(const PinholeCamera& cam, Eigen::Isometry3d& T_cw,
                              const std::vector<Eigen::Vector3d>& points_w, const std::vector<Observation>& obs,
                              const PoseOptimConfig& cfg, const std::vector<bool>* initial_outliers) {
  const auto start = std::chrono::steady_clock::now();
  if (points_w.size() != obs.size())
    throw std::invalid_argument("optimize_pose: points_w and obs differ in size");
  if (initial_outliers && initial_outliers->size() != obs.size())
    throw std::invalid_argument("optimize_pose: initial_outliers and obs differ in size");

  const std::size_t n = obs.size();
  PoseOptimResult result;
  result.outlier.assign(n, false);
  if (initial_outliers) result.outlier = *initial_outliers;
  std::vector<bool> active(n);
  const KernelConfig& kernel = cfg.kernel;
  double alpha = initial_alpha(kernel);

  std::unique_ptr<CeresPoseSolver> ceres_solver;
  if (cfg.solver == PoseSolver::Ceres)
    ceres_solver = std::make_unique<CeresPoseSolver>(cam, points_w, obs, kernel, alpha);
  AlphaSamples samples(kernel.fit);
  double e[3];

  for (int round = 0; round < cfg.rounds; ++round) {
    int n_active = 0;
    for (std::size_t i = 0; i < n; ++i) {
      active[i] = !kernel.chi2_gates && round > 0 ? true : !result.outlier[i];
      n_active += active[i];
    }
    if (n_active < kMinActive) break;
    if (kernel.type == KernelType::BarronAdaptive) {
      // Alternation: fit alpha on the active residuals at the current pose, then solve with it fixed.
      samples.clear();
      for (std::size_t i = 0; i < n; ++i) {
        if (!active[i]) continue;
        const int dof = whitened_residual(cam, obs[i], T_cw * points_w[i], e, nullptr);
        samples.add({e, static_cast<std::size_t>(dof)});
      }
      alpha = fit_alpha(kernel, samples.samples(), alpha);
    }
    if (ceres_solver)
      ceres_solver->solve(T_cw, obs, active, alpha, cfg.iterations_per_round);
    else
      solve_dedicated(cam, T_cw, points_w, obs, active, kernel, alpha, cfg.iterations_per_round);

    // Re-classify every observation (inactive ones too: they can come back).
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d p_c = T_cw * points_w[i];
      const int dof = whitened_residual(cam, obs[i], p_c, e, nullptr);
      double chi2 = 0;
      for (int k = 0; k < dof; ++k) chi2 += e[k] * e[k];
      result.outlier[i] = p_c.z() <= 0.0 || chi2 > chi2_threshold(dof);
    }
  }
  result.inliers = 0;
  for (std::size_t i = 0; i < n; ++i) result.inliers += !result.outlier[i];
  result.alpha = alpha;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace varslam::optim
