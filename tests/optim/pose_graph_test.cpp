#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <random>
#include <stdexcept>
#include <string>

#include "optim/pose_graph.hpp"

namespace varslam::optim {
namespace {

Eigen::Isometry3d pose(const Eigen::Vector3d& rotation_vector, const Eigen::Vector3d& translation) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double angle = rotation_vector.norm();
  if (angle > 0) T.linear() = Eigen::AngleAxisd(angle, rotation_vector / angle).toRotationMatrix();
  T.translation() = translation;
  return T;
}

Eigen::Vector3d camera_centre(const Eigen::Isometry3d& T_cw) { return T_cw.inverse().translation(); }

double max_rotation_error(const std::vector<Eigen::Isometry3d>& a, const std::vector<Eigen::Isometry3d>& b) {
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst, Eigen::AngleAxisd(a[i].rotation().transpose() * b[i].rotation()).angle());
  return worst;
}

PoseGraphEdge edge_from_poses(const std::vector<Eigen::Isometry3d>& T_cw, int from, int to, double weight = 1.0) {
  return {from, to, T_cw[static_cast<std::size_t>(from)] * T_cw[static_cast<std::size_t>(to)].inverse(), weight};
}

/// Ground-truth T_cw of `n` cameras on a circle of radius 5 m, facing along it, with some height and tilt wobble.
std::vector<Eigen::Isometry3d> circle_trajectory(int n) {
  std::vector<Eigen::Isometry3d> T_cw;
  for (int i = 0; i < n; ++i) {
    const double theta = 2.0 * M_PI * i / n;
    const Eigen::Vector3d centre(5.0 * std::cos(theta), 5.0 * std::sin(theta), 0.3 * std::sin(3 * theta));
    const Eigen::Vector3d rv(0.05 * std::sin(2 * theta), 0.05 * std::cos(theta), theta);
    const Eigen::Isometry3d T_wc = pose(rv, centre);
    T_cw.push_back(T_wc.inverse());
  }
  return T_cw;
}

/// A small random SE(3) perturbation: rotation of ~sigma_rot rad per axis, translation of ~sigma_trans m.
Eigen::Isometry3d random_perturbation(std::mt19937_64& rng, double sigma_rot, double sigma_trans) {
  std::normal_distribution<double> n01(0.0, 1.0);
  const Eigen::Vector3d rv(n01(rng), n01(rng), n01(rng));
  const Eigen::Vector3d t(n01(rng), n01(rng), n01(rng));
  return pose(sigma_rot * rv, sigma_trans * t);
}

/// Chains T_cw[i+1] = T_i,i+1^-1 * T_cw[i] from the true first pose with noisy odometry: the initial guess drifts.
std::vector<Eigen::Isometry3d> drifted_by_noisy_odometry(const std::vector<Eigen::Isometry3d>& truth, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::vector<Eigen::Isometry3d> T_cw{truth[0]};
  for (std::size_t i = 0; i + 1 < truth.size(); ++i) {
    const Eigen::Isometry3d odo = truth[i] * truth[i + 1].inverse() * random_perturbation(rng, 0.02, 0.05);
    T_cw.push_back(odo.inverse() * T_cw.back());
  }
  return T_cw;
}

double max_position_error(const std::vector<Eigen::Isometry3d>& a, const std::vector<Eigen::Isometry3d>& b) {
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, (camera_centre(a[i]) - camera_centre(b[i])).norm());
  return worst;
}

std::vector<bool> only_first_fixed(std::size_t n) {
  std::vector<bool> fixed(n, false);
  fixed[0] = true;
  return fixed;
}

TEST(PoseGraph, LoopEdgeRemovesAccumulatedDriftOnACircle) {
  constexpr int kN = 30;
  const std::vector<Eigen::Isometry3d> truth = circle_trajectory(kN);
  PoseGraphProblem problem;
  problem.T_cw = drifted_by_noisy_odometry(truth, 7);
  problem.fixed = only_first_fixed(kN);
  for (int i = 0; i + 1 < kN; ++i) problem.edges.push_back(edge_from_poses(truth, i, i + 1));
  const PoseGraphEdge loop = edge_from_poses(truth, kN - 1, 0);
  problem.edges.push_back(loop);

  const double initial_drift = max_position_error(problem.T_cw, truth);
  ASSERT_GT(initial_drift, 0.3);  // the test needs real drift to mean anything
  const PoseGraphEdgeError loop_before = pose_graph_edge_error(problem.T_cw, loop);
  ASSERT_GT(loop_before.translation, 0.3);

  const PoseGraphResult r = optimize_pose_graph(problem, PoseGraphConfig{});
  const double final_error = max_position_error(problem.T_cw, truth);
  std::cout << "[ pose graph ] circle N=30: drift " << initial_drift << " m -> " << final_error << " m in "
            << r.iterations << " iterations, cost " << r.initial_cost << " -> " << r.final_cost << "\n";
  EXPECT_LT(final_error, 0.2 * initial_drift);
  EXPECT_LT(final_error, 1e-4);  // edges are exact, so the optimum is the ground truth
  EXPECT_LT(max_rotation_error(problem.T_cw, truth), 1e-6);
  const PoseGraphEdgeError loop_after = pose_graph_edge_error(problem.T_cw, loop);
  EXPECT_LT(loop_after.translation, 1e-5);
  EXPECT_LT(loop_after.rotation, 1e-6);
  EXPECT_LT(r.final_cost, 1e-6 * r.initial_cost);
  EXPECT_TRUE(r.converged);
}

double rms_position_error(const std::vector<Eigen::Isometry3d>& a, const std::vector<Eigen::Isometry3d>& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (camera_centre(a[i]) - camera_centre(b[i])).squaredNorm();
  return std::sqrt(sum / static_cast<double>(a.size()));
}

TEST(PoseGraph, NoisyOdometryWithExactLoopEdgeSpreadsTheDrift) {
  // The realistic case: the odometry edges carry the noise, only the loop edge is exact; optimisation
  // must spread the loop's discrepancy over the chain instead of leaving it at the end. Weights are the
  // inverse noise variances (0.02 rad, 0.05 m per step).
  constexpr int kN = 30;
  const std::vector<Eigen::Isometry3d> truth = circle_trajectory(kN);
  PoseGraphConfig cfg;
  cfg.rotation_weight = 1.0 / (0.02 * 0.02);
  cfg.translation_weight = 1.0 / (0.05 * 0.05);
  double before_sum = 0, after_sum = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    PoseGraphProblem problem;
    problem.T_cw = drifted_by_noisy_odometry(truth, seed);
    problem.fixed = only_first_fixed(kN);
    for (int i = 0; i + 1 < kN; ++i) problem.edges.push_back(edge_from_poses(problem.T_cw, i, i + 1));
    const PoseGraphEdge loop = edge_from_poses(truth, kN - 1, 0, 1e4);
    problem.edges.push_back(loop);
    const double before = rms_position_error(problem.T_cw, truth);
    optimize_pose_graph(problem, cfg);
    const double after = rms_position_error(problem.T_cw, truth);
    EXPECT_LT(pose_graph_edge_error(problem.T_cw, loop).translation, 1e-4) << "seed " << seed;
    before_sum += before;
    after_sum += after;
  }
  std::cout << "[ pose graph ] noisy odometry, exact loop: mean RMS position error " << before_sum / 10 << " m -> "
            << after_sum / 10 << " m\n";
  EXPECT_LT(after_sum, 0.5 * before_sum);
}

TEST(PoseGraph, ConsistentGraphStaysPut) {
  const std::vector<Eigen::Isometry3d> truth = circle_trajectory(20);
  PoseGraphProblem problem;
  problem.T_cw = drifted_by_noisy_odometry(truth, 3);  // any poses: the edges are computed from them
  problem.fixed = only_first_fixed(problem.T_cw.size());
  for (int i = 0; i + 1 < 20; ++i) problem.edges.push_back(edge_from_poses(problem.T_cw, i, i + 1));
  problem.edges.push_back(edge_from_poses(problem.T_cw, 19, 0));
  problem.edges.push_back(edge_from_poses(problem.T_cw, 5, 12));
  const std::vector<Eigen::Isometry3d> before = problem.T_cw;

  const PoseGraphResult r = optimize_pose_graph(problem, PoseGraphConfig{});
  EXPECT_LT(r.initial_cost, 1e-20);
  EXPECT_LT(r.final_cost, 1e-20);
  for (std::size_t i = 0; i < before.size(); ++i)
    EXPECT_TRUE(problem.T_cw[i].isApprox(before[i], 1e-9)) << "vertex " << i;
}

TEST(PoseGraph, FixedVerticesAreNotMoved) {
  constexpr int kN = 30;
  const std::vector<Eigen::Isometry3d> truth = circle_trajectory(kN);
  PoseGraphProblem problem;
  problem.T_cw = drifted_by_noisy_odometry(truth, 5);
  problem.fixed.assign(kN, false);
  problem.fixed[0] = problem.fixed[15] = problem.fixed[29] = true;
  for (int i = 0; i + 1 < kN; ++i) problem.edges.push_back(edge_from_poses(truth, i, i + 1));
  problem.edges.push_back(edge_from_poses(truth, kN - 1, 0));
  const std::vector<Eigen::Isometry3d> before = problem.T_cw;

  optimize_pose_graph(problem, PoseGraphConfig{});
  int moved = 0;
  for (int i = 0; i < kN; ++i) {
    const std::size_t k = static_cast<std::size_t>(i);
    if (problem.fixed[k]) {
      EXPECT_EQ(problem.T_cw[k].matrix(), before[k].matrix()) << "fixed vertex " << i << " moved";
    } else {
      moved += (camera_centre(problem.T_cw[k]) - camera_centre(before[k])).norm() > 1e-3;
    }
  }
  EXPECT_GT(moved, 20);  // the free ones did move
}

TEST(PoseGraph, HeavierEdgeWinsAConflictByItsWeightRatio) {
  // Two conflicting measurements of the same relative pose (rotations about one axis, so the weighted
  // least-squares optimum is the weighted mean of angle and translation).
  PoseGraphProblem problem;
  problem.T_cw = {Eigen::Isometry3d::Identity(), pose({0, 0, 0.3}, {0.5, 0, 0})};
  problem.fixed = {true, false};
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 3).normalized();
  const Eigen::Isometry3d heavy = pose(0.2 * axis, {1.0, 0.0, 0.0});
  const Eigen::Isometry3d light = pose(0.4 * axis, {1.2, 0.3, 0.0});
  problem.edges = {{0, 1, heavy, 100.0}, {0, 1, light, 1.0}};

  const PoseGraphResult r = optimize_pose_graph(problem, PoseGraphConfig{});
  const PoseGraphEdgeError heavy_err = pose_graph_edge_error(problem.T_cw, problem.edges[0]);
  const PoseGraphEdgeError light_err = pose_graph_edge_error(problem.T_cw, problem.edges[1]);
  EXPECT_LT(heavy_err.translation, 0.02 * light_err.translation);
  EXPECT_LT(heavy_err.rotation, 0.02 * light_err.rotation);

  const Eigen::Isometry3d T_01 = problem.T_cw[0] * problem.T_cw[1].inverse();
  const Eigen::Vector3d expected_t = (100.0 * heavy.translation() + light.translation()) / 101.0;
  EXPECT_LT((T_01.translation() - expected_t).norm(), 1e-6);
  const Eigen::AngleAxisd aa(T_01.rotation());
  EXPECT_NEAR(aa.angle(), (100.0 * 0.2 + 0.4) / 101.0, 1e-6);
  EXPECT_LT((aa.axis() - axis).norm(), 1e-6);
  EXPECT_TRUE(r.converged);
}

TEST(PoseGraph, RotationAndTranslationWeightsScaleTheCost) {
  PoseGraphProblem problem;
  problem.T_cw = {Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()};
  problem.fixed = {true, true};  // nothing moves: only the cost is compared
  problem.edges = {{0, 1, pose({0.1, 0, 0}, {0.2, 0, 0}), 3.0}};
  PoseGraphConfig cfg;
  cfg.rotation_weight = 2.0;
  cfg.translation_weight = 5.0;
  const PoseGraphResult r = optimize_pose_graph(problem, cfg);
  EXPECT_NEAR(r.initial_cost, 0.5 * 3.0 * (2.0 * 0.1 * 0.1 + 5.0 * 0.2 * 0.2), 1e-12);
}

TEST(PoseGraph, RobustLossLimitsTheInfluenceOfABadEdge) {
  // A wrong edge (1 m off) across a well-connected circle (each vertex linked exactly to its next 4): bending
  // the graph to satisfy it costs many exact edges, so a redescending loss leaves the graph much closer
  // to the truth than plain least squares.
  constexpr int kN = 30;
  const std::vector<Eigen::Isometry3d> truth = circle_trajectory(kN);
  auto run = [&](PoseGraphLoss loss) {
    PoseGraphProblem problem;
    problem.T_cw = truth;
    problem.fixed = only_first_fixed(kN);
    for (int i = 0; i < kN; ++i)
      for (int k = 1; k <= 4; ++k) problem.edges.push_back(edge_from_poses(truth, i, (i + k) % kN));
    PoseGraphEdge bad = edge_from_poses(truth, 0, kN / 2);
    bad.T_from_to.translation() += Eigen::Vector3d(1.0, 0, 0);
    problem.edges.push_back(bad);
    PoseGraphConfig cfg;
    cfg.loss = loss;
    cfg.loss_scale = 0.1;
    cfg.max_iterations = 50;
    optimize_pose_graph(problem, cfg);
    return max_position_error(problem.T_cw, truth);
  };
  const double plain = run(PoseGraphLoss::None);
  const double cauchy = run(PoseGraphLoss::Cauchy);
  const double huber = run(PoseGraphLoss::Huber);
  EXPECT_GT(plain, 0.05);
  EXPECT_LT(cauchy, 0.2 * plain);
  EXPECT_LT(huber, plain);
}

TEST(PoseGraph, RejectsInvalidProblems) {
  PoseGraphProblem problem;
  problem.T_cw.assign(3, Eigen::Isometry3d::Identity());
  problem.edges = {{0, 3, Eigen::Isometry3d::Identity(), 1.0}};
  EXPECT_THROW(optimize_pose_graph(problem, {}), std::invalid_argument);
  problem.edges = {{1, 1, Eigen::Isometry3d::Identity(), 1.0}};
  EXPECT_THROW(optimize_pose_graph(problem, {}), std::invalid_argument);
  problem.edges = {{0, 1, Eigen::Isometry3d::Identity(), 0.0}};
  EXPECT_THROW(optimize_pose_graph(problem, {}), std::invalid_argument);
  problem.edges = {{0, 1, Eigen::Isometry3d::Identity(), 1.0}};
  problem.fixed = {true};
  EXPECT_THROW(optimize_pose_graph(problem, {}), std::invalid_argument);
}

TEST(PoseGraph, TimingOf200VerticesAnd2000Edges) {
  // Not asserted (timing belongs to benchmarks): prints and records the solve time of a loop-closing-sized
  // graph. Random-walk trajectory, noisy odometry + covisibility-like edges to the 10 previous vertices and
  // one random long-range edge per vertex.
  constexpr int kN = 200;
  std::mt19937_64 rng(42);
  std::vector<Eigen::Isometry3d> truth{Eigen::Isometry3d::Identity()};
  for (int i = 1; i < kN; ++i) truth.push_back(random_perturbation(rng, 0.05, 0.2) * truth.back());
  PoseGraphProblem problem;
  problem.T_cw = drifted_by_noisy_odometry(truth, 9);
  problem.fixed = only_first_fixed(kN);
  auto noisy_edge = [&](int from, int to) {
    PoseGraphEdge e = edge_from_poses(truth, from, to);
    e.T_from_to = e.T_from_to * random_perturbation(rng, 0.002, 0.005);
    return e;
  };
  for (int i = 0; i < kN; ++i)
    for (int j = std::max(0, i - 9); j < i; ++j) problem.edges.push_back(noisy_edge(j, i));
  std::uniform_int_distribution<int> any(0, kN - 1);
  for (int i = 0; i < kN; ++i) {
    const int j = any(rng);
    if (j != i) problem.edges.push_back(noisy_edge(i, j));
  }
  const double initial_drift = max_position_error(problem.T_cw, truth);

  const auto t0 = std::chrono::steady_clock::now();
  const PoseGraphResult r = optimize_pose_graph(problem, PoseGraphConfig{});
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "[ pose graph ] " << kN << " vertices, " << problem.edges.size() << " edges: " << ms << " ms, "
            << r.iterations << " iterations, drift " << initial_drift << " m -> "
            << max_position_error(problem.T_cw, truth) << " m\n";
  ::testing::Test::RecordProperty("pose_graph_200v_ms", std::to_string(ms));
  EXPECT_LT(max_position_error(problem.T_cw, truth), 0.2 * initial_drift);
}

}  // namespace
}  // namespace varslam::optim
