#include "optim/pose_graph.hpp"

#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/rotation.h>
#include <ceres/solver.h>

namespace varslam::optim {
namespace {

/// Angle-axis (log map) of a unit quaternion; Ceres' conversion takes (w, x, y, z) and picks the short way.
template <typename T>
Eigen::Matrix<T, 3, 1> quaternion_log(const Eigen::Quaternion<T>& q) {
  const T wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
  Eigen::Matrix<T, 3, 1> aa;
  ceres::QuaternionToAngleAxis(wxyz, aa.data());
  return aa;
}

/// Residual of one edge over (q_from, t_from, q_to, t_to), each vertex stored as T_cw = (Eigen quaternion
/// x,y,z,w; translation). Estimated T_from_to = T_from * T_to^-1.
class EdgeResidual {
 public:
  EdgeResidual(const Eigen::Isometry3d& T_meas, double rotation_scale, double translation_scale)
      : q_meas_inv_(Eigen::Quaterniond(T_meas.rotation()).conjugate()),
        t_meas_(T_meas.translation()),
        rotation_scale_(rotation_scale),
        translation_scale_(translation_scale) {}

  template <typename T>
  bool operator()(const T* q_from_p, const T* t_from_p, const T* q_to_p, const T* t_to_p, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_from(q_from_p), q_to(q_to_p);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_from(t_from_p), t_to(t_to_p);
    const Eigen::Quaternion<T> q_est = q_from * q_to.conjugate();
    const Eigen::Matrix<T, 3, 1> t_est = t_from - q_est * t_to;
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r.template head<3>() = T(rotation_scale_) * quaternion_log(Eigen::Quaternion<T>(q_meas_inv_.cast<T>() * q_est));
    r.template tail<3>() = T(translation_scale_) * (t_est - t_meas_.cast<T>());
    return true;
  }

 private:
  Eigen::Quaterniond q_meas_inv_;
  Eigen::Vector3d t_meas_;
  double rotation_scale_, translation_scale_;
};

/// Vertex parameters in the layout Ceres optimises: Eigen quaternion coefficients (x, y, z, w) + translation.
struct VertexBlocks {
  std::vector<std::array<double, 4>> q;
  std::vector<std::array<double, 3>> t;

  explicit VertexBlocks(const std::vector<Eigen::Isometry3d>& T_cw) : q(T_cw.size()), t(T_cw.size()) {
    for (std::size_t i = 0; i < T_cw.size(); ++i) {
      Eigen::Map<Eigen::Quaterniond>(q[i].data()) = Eigen::Quaterniond(T_cw[i].rotation()).normalized();
      Eigen::Map<Eigen::Vector3d>(t[i].data()) = T_cw[i].translation();
    }
  }

  Eigen::Isometry3d pose(std::size_t i) const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Map<const Eigen::Quaterniond>(q[i].data()).normalized().toRotationMatrix();
    T.translation() = Eigen::Map<const Eigen::Vector3d>(t[i].data());
    return T;
  }
};

void validate(const PoseGraphProblem& problem) {
  const int n = static_cast<int>(problem.T_cw.size());
  if (!problem.fixed.empty() && problem.fixed.size() != problem.T_cw.size())
    throw std::invalid_argument("optimize_pose_graph: fixed must be empty or have one entry per vertex");
  for (const PoseGraphEdge& e : problem.edges) {
    if (e.from < 0 || e.from >= n || e.to < 0 || e.to >= n || e.from == e.to)
      throw std::invalid_argument("optimize_pose_graph: bad edge " + std::to_string(e.from) + " -> " +
                                  std::to_string(e.to) + " with " + std::to_string(n) + " vertices");
    if (!(e.weight > 0.0)) throw std::invalid_argument("optimize_pose_graph: edge weight must be > 0");
  }
}

std::unique_ptr<ceres::LossFunction> make_loss(const PoseGraphConfig& cfg) {
  switch (cfg.loss) {
    case PoseGraphLoss::Huber: return std::make_unique<ceres::HuberLoss>(cfg.loss_scale);
    case PoseGraphLoss::Cauchy: return std::make_unique<ceres::CauchyLoss>(cfg.loss_scale);
    case PoseGraphLoss::None: break;
  }
  return nullptr;
}

ceres::Solver::Options solver_options(const PoseGraphConfig& cfg) {
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = cfg.max_iterations;
  options.num_threads = cfg.max_threads;
  options.function_tolerance = cfg.function_tolerance;
  options.gradient_tolerance = cfg.gradient_tolerance;
  options.parameter_tolerance = cfg.parameter_tolerance;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  return options;
}

}  // namespace

PoseGraphResult optimize_pose_graph(PoseGraphProblem& problem, const PoseGraphConfig& cfg) {
  validate(problem);
  PoseGraphResult result;
  if (problem.edges.empty()) {
    result.converged = true;
    return result;
  }

  VertexBlocks blocks(problem.T_cw);
  ceres::EigenQuaternionManifold quaternion_manifold;
  const std::unique_ptr<ceres::LossFunction> loss = make_loss(cfg);
  ceres::Problem::Options po;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // one loss and one manifold shared by all blocks
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(po);

  for (const PoseGraphEdge& e : problem.edges) {
    const double rotation_scale = std::sqrt(e.weight * cfg.rotation_weight);
    const double translation_scale = std::sqrt(e.weight * cfg.translation_weight);
    auto* cost = new ceres::AutoDiffCostFunction<EdgeResidual, 6, 4, 3, 4, 3>(
        new EdgeResidual(e.T_from_to, rotation_scale, translation_scale));
    ceres_problem.AddResidualBlock(cost, loss.get(), blocks.q[e.from].data(), blocks.t[e.from].data(),
                                   blocks.q[e.to].data(), blocks.t[e.to].data());
  }

  for (std::size_t i = 0; i < problem.T_cw.size(); ++i) {
    if (!ceres_problem.HasParameterBlock(blocks.q[i].data())) continue;  // in no edge
    ceres_problem.SetManifold(blocks.q[i].data(), &quaternion_manifold);
    if (!problem.fixed.empty() && problem.fixed[i]) {
      ceres_problem.SetParameterBlockConstant(blocks.q[i].data());
      ceres_problem.SetParameterBlockConstant(blocks.t[i].data());
    }
  }

  ceres::Solver::Summary summary;
  ceres::Solve(solver_options(cfg), &ceres_problem, &summary);

  for (std::size_t i = 0; i < problem.T_cw.size(); ++i) {
    const bool is_fixed = !problem.fixed.empty() && problem.fixed[i];
    if (!is_fixed && ceres_problem.HasParameterBlock(blocks.q[i].data())) problem.T_cw[i] = blocks.pose(i);
  }
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  return result;
}

PoseGraphEdgeError pose_graph_edge_error(const std::vector<Eigen::Isometry3d>& T_cw, const PoseGraphEdge& edge) {
  const Eigen::Isometry3d T_est = T_cw.at(static_cast<std::size_t>(edge.from)) *
                                  T_cw.at(static_cast<std::size_t>(edge.to)).inverse();
  const Eigen::Matrix3d dR = edge.T_from_to.rotation().transpose() * T_est.rotation();
  return {Eigen::AngleAxisd(dR).angle(), (T_est.translation() - edge.T_from_to.translation()).norm()};
}

}  // namespace varslam::optim
