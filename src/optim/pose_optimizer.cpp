#include "optim/pose_optimizer.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <utility>

#include <ceres/problem.h>
#include <ceres/solver.h>

#include "core/geometry.hpp"

namespace varslam::optim {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

constexpr int kMinActive = 5;  // below this a 6-DoF pose is not worth optimising

/// Normal equations of the robust cost at one pose. The Gauss-Newton Hessian of rho(|e|^2) is
/// J^T (rho' I + 2 rho'' e e^T) J: `H_irls` holds the first part (plain IRLS, a majorizer: safe far from the
/// optimum), `H_radial` the change of curvature along each e, rho' + 2 s rho'' - rho', with the curvature
/// clamped at 0 (negative for redescending kernels on outliers) so that H_irls + H_radial stays PSD.
struct NormalEquations {
  Matrix6d H_irls, H_radial;
  Vector6d b;
  Matrix6d H(bool newton) const { return newton ? Matrix6d(H_irls + H_radial) : H_irls; }
};

/// Adds one observation's terms to the normal equations, with its Jacobian at fixed size: Dof rows of
/// de/dp_c [-[p_c]x | I], the pose Jacobian of the left update.
template <int Dof>
void accumulate(const Eigen::Matrix3d& de_dpc, const Eigen::Vector3d& p_c, const double* e, double sq,
                const double rho[3], NormalEquations& ne) {
  Eigen::Matrix<double, Dof, 6> J;
  J.template leftCols<3>().noalias() = de_dpc.topRows<Dof>() * (-skew(p_c));
  J.template rightCols<3>() = de_dpc.topRows<Dof>();
  const Eigen::Map<const Eigen::Matrix<double, Dof, 1>> ev(e);
  const Vector6d Jte = J.transpose() * ev;
  ne.H_irls.noalias() += rho[1] * J.transpose() * J;
  if (rho[2] != 0.0 && sq > 0.0) {
    const double radial = std::max(rho[1] + 2.0 * sq * rho[2], 0.0);
    ne.H_radial.noalias() += ((radial - rho[1]) / sq) * Jte * Jte.transpose();
  }
  ne.b.noalias() += rho[1] * Jte;
}

/// Robust cost (and optionally the normal equations) of the active observations at T.
double linearize(const PinholeCamera& cam, const Eigen::Isometry3d& T, const std::vector<Eigen::Vector3d>& points,
                 const std::vector<Observation>& obs, const std::vector<bool>& active, const Kernel& kernel,
                 NormalEquations* ne) {
  double cost = 0;
  if (ne) {
    ne->H_irls.setZero();
    ne->H_radial.setZero();
    ne->b.setZero();
  }
  double e[3] = {}, rho[3] = {};  // zeroed: GCC cannot see that evaluate() always writes rho
  Eigen::Matrix3d de_dpc;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    if (!active[i]) continue;
    const Eigen::Vector3d p_c = T * points[i];
    const int dof = whitened_residual(cam, obs[i], p_c, e, ne ? &de_dpc : nullptr);
    const double sq = dof == 3 ? e[0] * e[0] + e[1] * e[1] + e[2] * e[2] : e[0] * e[0] + e[1] * e[1];
    kernel.evaluate(dof, sq, rho);
    cost += rho[0];
    if (!ne) continue;
    if (dof == 3)
      accumulate<3>(de_dpc, p_c, e, sq, rho, *ne);
    else
      accumulate<2>(de_dpc, p_c, e, sq, rho, *ne);
  }
  return 0.5 * cost;
}

/// Levenberg-Marquardt on the 6-DoF left update, Marquardt-scaled damping. An iteration is one trial step.
/// Steps start on the IRLS Hessian (robust far from the optimum) unless `start_newton`, and switch to the full
/// Gauss-Newton Hessian once an accepted step changed the cost by under 1%: IRLS alone converges only linearly
/// on smooth kernels (Barron alpha = 1 needed ~2x the iterations of Huber, whose inliers are purely
/// quadratic). A rejected full step falls back to IRLS before any extra damping. Returns the trial steps taken.
int solve_dedicated(const PinholeCamera& cam, Eigen::Isometry3d& T, const std::vector<Eigen::Vector3d>& points,
                    const std::vector<Observation>& obs, const std::vector<bool>& active, const Kernel& kernel,
                    int iterations, bool start_newton) {
  NormalEquations ne, ne_new;
  double cost = linearize(cam, T, points, obs, active, kernel, &ne);
  double lambda = 1e-4;
  bool newton = start_newton;
  int steps = 0;
  for (int it = 0; it < iterations; ++it) {
    const Matrix6d H = ne.H(newton);
    Matrix6d A = H;
    A.diagonal() += lambda * H.diagonal().cwiseMax(1e-9);
    const Vector6d delta = A.ldlt().solve(-ne.b);
    if (!delta.allFinite()) break;
    const Eigen::Isometry3d T_new = se3_left_update(T, delta);
    const double cost_new = linearize(cam, T_new, points, obs, active, kernel, &ne_new);
    ++steps;
    if (cost_new < cost) {
      // Same stopping rule as Ceres' default function_tolerance, so both solvers do comparable work.
      const bool converged = delta.squaredNorm() < 1e-20 || cost - cost_new < 1e-6 * cost;
      newton = newton || cost - cost_new < 1e-2 * cost;
      T = T_new;
      std::swap(ne, ne_new);
      cost = cost_new;
      lambda = std::max(lambda * 0.1, 1e-12);
      if (converged) break;
    } else if (newton) {
      newton = false;
    } else {
      lambda *= 10.0;
      if (lambda > 1e10) break;
    }
  }
  T = normalized(T);
  return steps;
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

  /// Returns Ceres' iteration count.
  int solve(Eigen::Isometry3d& T, const std::vector<Observation>& obs, const std::vector<bool>& active,
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
    return static_cast<int>(summary.iterations.size()) - 1;
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
  if (cfg.observer) cfg.observer(cam, T_cw, points_w, obs, cfg, initial_outliers);
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
      alpha = fit_alpha(kernel, samples.samples(), alpha).applied;
    }
    if (ceres_solver)
      result.iterations += ceres_solver->solve(T_cw, obs, active, alpha, cfg.iterations_per_round);
    else
      result.iterations += solve_dedicated(cam, T_cw, points_w, obs, active, Kernel(kernel, alpha),
                                           cfg.iterations_per_round, round > 0);

    // Re-classify every observation (inactive ones too: they can come back).
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d p_c = T_cw * points_w[i];
      int dof = 0;
      const double chi2 = whitened_chi2(cam, obs[i], p_c, dof);
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
