#include "optim/schur_lm.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "core/geometry.hpp"

namespace varslam::optim {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix63d = Eigen::Matrix<double, 6, 3>;

// Ceres' defaults (Solver::Options), which the Ceres-based solver used: keeping them keeps its convergence.
constexpr double kInitialRadius = 1e4;
constexpr double kMaxRadius = 1e16;
constexpr double kMinRadius = 1e-32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr double kFunctionTolerance = 1e-6;
constexpr double kGradientTolerance = 1e-10;
constexpr double kParameterTolerance = 1e-8;
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;

/// Levenberg-Marquardt damping of one diagonal entry d of J^T J at trust-region radius `radius`, as Ceres applies it
/// with Jacobi scaling: the column is scaled by 1 / (1 + sqrt(d)), its squared norm clamped, then divided by the
/// radius; expressed back in the unscaled variable.
double damping(double d, double radius) {
  const double s = 1.0 / (1.0 + std::sqrt(d));
  return std::clamp(d * s * s, kMinDiagonal, kMaxDiagonal) / (s * s * radius);
}

}  // namespace

struct SchurLm::Linearized {
  std::vector<Eigen::Matrix<double, 3, 6>> Jp;  // per observation, robustified; rows past the dof are zero
  std::vector<Eigen::Matrix3d> Jl;
  std::vector<Eigen::Vector3d> r;
  std::vector<Matrix63d> Hpl;                   // Jp^T Jl
  std::vector<Matrix6d> Hpp;                    // per pose variable
  std::vector<Vector6d> gp;
  std::vector<Eigen::Matrix3d> Hll;             // per point
  std::vector<Eigen::Vector3d> gl;
  // Solve scratch.
  std::vector<Eigen::Matrix3d> Vinv;
  Eigen::MatrixXd S;
  Eigen::VectorXd b;
  double model_change = 0;
};

SchurLm::SchurLm(const PinholeCamera& camera, const std::vector<BaObservation>& observations,
                 std::vector<bool> pose_fixed, double* poses, double* points, std::size_t points_count)
    : camera_(camera),
      observations_(observations),
      pose_fixed_(std::move(pose_fixed)),
      poses_(poses),
      points_(points),
      poses_count_(pose_fixed_.size()),
      points_count_(points_count) {}

double SchurLm::evaluate(const double* poses, const double* points, Linearized* lin) const {
  if (lin) {
    for (auto& h : lin->Hpp) h.setZero();
    for (auto& g : lin->gp) g.setZero();
    for (auto& h : lin->Hll) h.setZero();
    for (auto& g : lin->gl) g.setZero();
  }
  rotations_.resize(poses_count_);
  translations_.resize(poses_count_);
  for (std::size_t k = 0; k < poses_count_; ++k) {
    rotations_[k] = Eigen::Map<const Eigen::Quaterniond>(poses + k * kPoseParams).toRotationMatrix();
    translations_[k] = Eigen::Map<const Eigen::Vector3d>(poses + k * kPoseParams + 4);
  }
  double cost = 0;
  double e[3];
  Eigen::Matrix3d de_dpc;
  for (std::size_t j = 0; j < observations_.size(); ++j) {
    if (!(*active_)[j]) continue;
    const BaObservation& o = observations_[j];
    const auto k = static_cast<std::size_t>(o.keyframe);
    const Eigen::Vector3d p_c =
        rotations_[k] * Eigen::Map<const Eigen::Vector3d>(points + static_cast<std::size_t>(o.point) * 3) +
        translations_[k];
    e[2] = 0;
    const int dof = whitened_residual(camera_, o.obs, p_c, e, lin ? &de_dpc : nullptr);
    Eigen::Map<Eigen::Vector3d> r(e);
    const double s = r.squaredNorm();
    const ceres::LossFunction* loss = dof == 3 ? stereo_loss_ : mono_loss_;
    double rho[3] = {s, 1.0, 0.0};
    if (loss) loss->Evaluate(s, rho);
    cost += 0.5 * rho[0];
    if (!lin) continue;
    // d e / d [w; v] = de_dpc [-[p_c]x, I] for the left update; rows past the dof are zero.
    Eigen::Matrix<double, 3, 6> Jp;
    Jp.leftCols<3>().noalias() = -de_dpc * skew(p_c);
    Jp.rightCols<3>() = de_dpc;
    Eigen::Matrix3d Jl;
    Jl.noalias() = de_dpc * rotations_[k];
    if (loss) {
      // Ceres' residual correction for a robust loss (Triggs et al.): the loss's curvature folded into r and J.
      const double sqrt_rho1 = std::sqrt(rho[1]);
      if (s > 0.0 && rho[2] > 0.0) {
        const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * s * rho[2] / rho[1]);
        const double alpha_sq_norm = alpha / s;
        const Eigen::Vector3d r0 = r;
        Jp = sqrt_rho1 * (Jp - alpha_sq_norm * r0 * (r0.transpose() * Jp));
        Jl = sqrt_rho1 * (Jl - alpha_sq_norm * r0 * (r0.transpose() * Jl));
        r *= sqrt_rho1 / (1.0 - alpha);
      } else {
        Jp *= sqrt_rho1;
        Jl *= sqrt_rho1;
        r *= sqrt_rho1;
      }
    }
    lin->Jp[j] = Jp;
    lin->Jl[j] = Jl;
    lin->r[j] = r;
    const int v = pose_var_[k];
    if (v >= 0) {
      lin->Hpl[j].noalias() = Jp.transpose() * Jl;
      lin->Hpp[v].noalias() += Jp.transpose() * Jp;
      lin->gp[v].noalias() += Jp.transpose() * r;
    }
    lin->Hll[o.point].noalias() += Jl.transpose() * Jl;
    lin->gl[o.point].noalias() += Jl.transpose() * r;
  }
  return cost;
}

bool SchurLm::solve_step(Linearized& lin, double radius, std::vector<double>& step_poses,
                         std::vector<double>& step_points) const {
  const auto vars = static_cast<Eigen::Index>(lin.Hpp.size());
  lin.S.setZero(6 * vars, 6 * vars);
  lin.b.resize(6 * vars);
  for (Eigen::Index v = 0; v < vars; ++v) {
    Matrix6d H = lin.Hpp[static_cast<std::size_t>(v)];
    for (int d = 0; d < 6; ++d) H(d, d) += damping(H(d, d), radius);
    lin.S.block<6, 6>(6 * v, 6 * v) = H;
    lin.b.segment<6>(6 * v) = -lin.gp[static_cast<std::size_t>(v)];
  }
  // Eliminate the points: S -= W V^-1 W^T, b -= W V^-1 (-g_l), one point at a time.
  for (std::size_t i = 0; i < points_count_; ++i) {
    if (!point_used_[i]) continue;
    Eigen::Matrix3d V = lin.Hll[i];
    for (int d = 0; d < 3; ++d) V(d, d) += damping(V(d, d), radius);
    // Damped J^T J of one point: positive definite unless degenerate, where the step fails as Ceres' would.
    const double det = V.determinant();
    if (!(det > 0.0) || !std::isfinite(det) || !(V(0, 0) > 0.0)) return false;
    lin.Vinv[i] = V.inverse();
    const std::vector<int>& obs = point_obs_[i];
    for (std::size_t a = 0; a < obs.size(); ++a) {
      const int va = pose_var_[static_cast<std::size_t>(observations_[static_cast<std::size_t>(obs[a])].keyframe)];
      if (va < 0) continue;
      const Matrix63d WV = lin.Hpl[static_cast<std::size_t>(obs[a])] * lin.Vinv[i];
      lin.b.segment<6>(6 * va).noalias() += WV * lin.gl[i];
      for (std::size_t c = a; c < obs.size(); ++c) {
        const int vc = pose_var_[static_cast<std::size_t>(observations_[static_cast<std::size_t>(obs[c])].keyframe)];
        if (vc < 0) continue;
        const Matrix6d block = WV * lin.Hpl[static_cast<std::size_t>(obs[c])].transpose();
        lin.S.block<6, 6>(6 * va, 6 * vc) -= block;
        if (c != a) lin.S.block<6, 6>(6 * vc, 6 * va) -= block.transpose();
      }
    }
  }
  Eigen::VectorXd dp;
  if (vars > 0) {
    const Eigen::LLT<Eigen::MatrixXd> llt(lin.S);
    if (llt.info() != Eigen::Success) return false;
    dp = llt.solve(lin.b);
  }
  std::fill(step_poses.begin(), step_poses.end(), 0.0);
  for (std::size_t k = 0; k < poses_count_; ++k)
    if (pose_var_[k] >= 0)
      Eigen::Map<Vector6d>(step_poses.data() + 6 * k) = dp.segment<6>(6 * pose_var_[k]);
  // Back-substitute the points and measure the step against the linear model (Ceres' model cost change).
  double model = 0;
  for (std::size_t i = 0; i < points_count_; ++i) {
    Eigen::Map<Eigen::Vector3d> dl(step_points.data() + 3 * i);
    if (!point_used_[i]) {
      dl.setZero();
      continue;
    }
    Eigen::Vector3d rhs = -lin.gl[i];
    for (const int j : point_obs_[i]) {
      const int v = pose_var_[static_cast<std::size_t>(observations_[static_cast<std::size_t>(j)].keyframe)];
      if (v >= 0) rhs.noalias() -= lin.Hpl[static_cast<std::size_t>(j)].transpose() * dp.segment<6>(6 * v);
    }
    dl = lin.Vinv[i] * rhs;
    for (const int j : point_obs_[i]) {
      const auto ju = static_cast<std::size_t>(j);
      Eigen::Vector3d Jdx = lin.Jl[ju] * dl;
      const int v = pose_var_[static_cast<std::size_t>(observations_[ju].keyframe)];
      if (v >= 0) Jdx.noalias() += lin.Jp[ju] * dp.segment<6>(6 * v);
      model -= Jdx.dot(lin.r[ju]) + 0.5 * Jdx.squaredNorm();
    }
  }
  lin.model_change = model;
  return std::isfinite(model);
}

SchurLmSummary SchurLm::solve(const std::vector<bool>& active, const ceres::LossFunction* mono_loss,
                              const ceres::LossFunction* stereo_loss, int max_iterations,
                              const SchurLmCallback& after) {
  active_ = &active;
  mono_loss_ = mono_loss;
  stereo_loss_ = stereo_loss;
  // Variables: non-fixed poses and points with at least one active observation (as Ceres drops unused blocks).
  std::vector<char> pose_used(poses_count_, 0);
  point_used_.assign(points_count_, 0);
  point_obs_.assign(points_count_, {});
  for (std::size_t j = 0; j < observations_.size(); ++j) {
    if (!active[j]) continue;
    pose_used[static_cast<std::size_t>(observations_[j].keyframe)] = 1;
    point_used_[static_cast<std::size_t>(observations_[j].point)] = 1;
    point_obs_[static_cast<std::size_t>(observations_[j].point)].push_back(static_cast<int>(j));
  }
  pose_var_.assign(poses_count_, -1);
  int vars = 0;
  for (std::size_t k = 0; k < poses_count_; ++k)
    if (pose_used[k] && !pose_fixed_[k]) pose_var_[k] = vars++;

  Linearized lin;
  lin.Jp.resize(observations_.size());
  lin.Jl.resize(observations_.size());
  lin.r.resize(observations_.size());
  lin.Hpl.resize(observations_.size());
  lin.Hpp.resize(static_cast<std::size_t>(vars));
  lin.gp.resize(static_cast<std::size_t>(vars));
  lin.Hll.resize(points_count_);
  lin.gl.resize(points_count_);
  lin.Vinv.resize(points_count_);

  SchurLmSummary summary;
  double cost = evaluate(poses_, points_, &lin);
  if (!std::isfinite(cost)) return summary;
  const auto gradient_small = [&] {
    double g = 0;
    for (const auto& x : lin.gp) g = std::max(g, x.cwiseAbs().maxCoeff());
    for (std::size_t i = 0; i < points_count_; ++i)
      if (point_used_[i]) g = std::max(g, lin.gl[i].cwiseAbs().maxCoeff());
    return g <= kGradientTolerance;
  };
  if (gradient_small()) {
    summary.converged = true;
    return summary;
  }
  const std::size_t pose_block = poses_count_ * kPoseParams;
  std::vector<double> step_poses(poses_count_ * 6), step_points(points_count_ * 3);
  std::vector<double> candidate_poses(poses_, poses_ + pose_block), candidate_points(points_, points_ + points_count_ * 3);
  double radius = kInitialRadius, decrease_factor = 2.0;
  for (int iteration = 1; iteration <= max_iterations; ++iteration) {
    summary.iterations = iteration;
    bool success = false;
    if (solve_step(lin, radius, step_poses, step_points) && lin.model_change > 0.0) {
      double x_norm2 = 0, step_norm2 = 0;
      for (std::size_t k = 0; k < poses_count_; ++k) {
        if (pose_var_[k] < 0) continue;
        const double* x = poses_ + k * kPoseParams;
        const double* dx = step_poses.data() + 6 * k;
        for (int d = 0; d < kPoseParams; ++d) x_norm2 += x[d] * x[d];
        for (int d = 0; d < 6; ++d) step_norm2 += dx[d] * dx[d];
        pose_plus(x, dx, candidate_poses.data() + k * kPoseParams);
      }
      for (std::size_t i = 0; i < points_count_; ++i) {
        if (!point_used_[i]) continue;
        for (std::size_t d = 3 * i; d < 3 * i + 3; ++d) {
          x_norm2 += points_[d] * points_[d];
          step_norm2 += step_points[d] * step_points[d];
          candidate_points[d] = points_[d] + step_points[d];
        }
      }
      if (std::sqrt(step_norm2) <= (std::sqrt(x_norm2) + kParameterTolerance) * kParameterTolerance) {
        summary.converged = true;
        return summary;
      }
      const double candidate_cost = evaluate(candidate_poses.data(), candidate_points.data(), nullptr);
      if (std::isfinite(candidate_cost)) {
        const double change = cost - candidate_cost;
        if (std::abs(change) <= kFunctionTolerance * cost) {
          summary.converged = true;
          return summary;
        }
        const double relative_decrease = change / lin.model_change;
        if (relative_decrease > kMinRelativeDecrease) {
          success = true;
          std::copy(candidate_poses.begin(), candidate_poses.end(), poses_);
          std::copy(candidate_points.begin(), candidate_points.end(), points_);
          cost = evaluate(poses_, points_, &lin);
          const double t = 2.0 * relative_decrease - 1.0;
          radius = std::min(kMaxRadius, radius / std::max(1.0 / 3.0, 1.0 - t * t * t));
          decrease_factor = 2.0;
        }
      }
    }
    if (!success) {
      radius /= decrease_factor;
      decrease_factor *= 2.0;
      if (radius < kMinRadius) {
        summary.converged = true;
        return summary;
      }
    } else if (gradient_small()) {
      summary.converged = true;
      return summary;
    }
    if (after && !after(iteration)) return summary;
  }
  return summary;
}

}  // namespace varslam::optim
