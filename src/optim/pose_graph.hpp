#pragma once
// SE(3) pose graph optimisation for loop closing (RGB-D: scale is observable, so no Sim(3)).
// Pure math: Eigen + Ceres only, no SLAM types.
#include <vector>

#include <Eigen/Geometry>

namespace varslam::optim {

/// A relative-pose measurement between two vertices.
/// T_from_to = T_from_w * T_w_to, i.e. T_cw[from] * T_cw[to].inverse() with T_cw camera-from-world.
struct PoseGraphEdge {
  int from = 0, to = 0;
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();
  double weight = 1.0;  // multiplies the edge's squared error (information scale); must be > 0
};

struct PoseGraphProblem {
  std::vector<Eigen::Isometry3d> T_cw;  // camera-from-world per vertex; optimised in place
  std::vector<bool> fixed;              // same size as T_cw, or empty (= none fixed; gauge then left to damping)
  std::vector<PoseGraphEdge> edges;
};

enum class PoseGraphLoss { None, Huber, Cauchy };

struct PoseGraphConfig {
  int max_iterations = 20;
  int max_threads = 1;  // 1 = deterministic
  // Scales of the squared rotation error (rad^2) and translation error (m^2) of every edge; the edge residual
  // is sqrt(weight * rotation_weight) * r_rot and sqrt(weight * translation_weight) * r_trans.
  double rotation_weight = 1.0;
  double translation_weight = 1.0;
  // Optional robust loss on each edge's weighted squared error (edges are normally verified: None).
  // loss_scale is the residual norm where the loss leaves the quadratic (Ceres' `a`).
  PoseGraphLoss loss = PoseGraphLoss::None;
  double loss_scale = 1.0;
  // Ceres stopping tolerances; tighter than Ceres' defaults because pose graphs are cheap and loop closing
  // wants the drift fully redistributed.
  double function_tolerance = 1e-10;
  double gradient_tolerance = 1e-12;
  double parameter_tolerance = 1e-10;
};

struct PoseGraphResult {
  double initial_cost = 0, final_cost = 0;  // 0.5 * sum of squared (weighted, robustified) residuals
  int iterations = 0;                       // Levenberg-Marquardt steps tried (successful + unsuccessful)
  bool converged = false;                   // a Ceres tolerance was met (not merely max_iterations)
};

/// Optimises the non-fixed T_cw of `problem` in place so that the relative poses agree with the edges.
/// Per edge the 6-D residual is [angle-axis(R_meas^T * R_est); t_est - t_meas] with (R_est, t_est) the
/// current T_from_to, so the translation error is expressed in the `from` frame. Parameterised as an Eigen
/// quaternion (EigenQuaternionManifold) plus a translation per vertex; sparse normal Cholesky;
/// Levenberg-Marquardt. Vertices in no edge are left untouched.
/// Throws std::invalid_argument on edges with out-of-range or equal endpoints, non-positive weights, or a
/// `fixed` of the wrong size.
PoseGraphResult optimize_pose_graph(PoseGraphProblem& problem, const PoseGraphConfig& cfg);

/// Discrepancy between an edge's measurement and the current poses (unweighted): the rotation angle (rad) of
/// R_meas^T * R_est and the norm (m) of t_est - t_meas. For diagnostics, e.g. checking a loop edge.
struct PoseGraphEdgeError {
  double rotation = 0, translation = 0;
};
PoseGraphEdgeError pose_graph_edge_error(const std::vector<Eigen::Isometry3d>& T_cw, const PoseGraphEdge& edge);

}  // namespace varslam::optim
