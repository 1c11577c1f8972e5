#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <random>

#include "optim/local_ba.hpp"
#include "optim/synthetic_problems.hpp"

namespace varslam::optim {
namespace {

BaConfig ba_config(KernelType type) {
  BaConfig cfg;
  cfg.kernel.type = type;
  return cfg;
}

// 6 keyframes (2 fixed), 300 points, 0.5 px noise at level 0. `perturbation` scales the initial error of
// the free keyframes (1 = 5 cm, 0.01 rad) and of the points (1 = 5 cm per axis).
SyntheticBa small_problem(unsigned seed, double perturbation = 1.0) {
  SyntheticBaOptions opt;
  opt.keyframes = 6;
  opt.fixed_keyframes = 2;
  opt.points = 300;
  opt.pixel_noise = 0.5;
  opt.translation_error *= perturbation;
  opt.rotation_error *= perturbation;
  opt.point_error *= perturbation;
  opt.seed = seed;
  return make_synthetic_ba(PinholeCamera{}, opt);
}

/// Replaces every `every`-th observation by a wrong match (random pixel, random depth).
void add_gross_outliers(const PinholeCamera& cam, SyntheticBa& s, int every) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (std::size_t j = 0; j < s.initial.observations.size(); j += every) {
    Observation& o = s.initial.observations[j].obs;
    o.uv << u01(rng) * cam.width, u01(rng) * cam.height;
    if (o.stereo()) o.u_right = std::max(0.0, o.uv.x() - cam.bf / (1.0 + 8.0 * u01(rng)));
  }
  s.truth.observations = s.initial.observations;
}

/// Turns a spatial block of points into a "moving object": every keyframe after the first observes it
/// displaced by k * step, consistently (noise kept). Returns the indices of the affected observations.
std::vector<bool> add_moving_object(const PinholeCamera& cam, SyntheticBa& s, const Eigen::Vector3d& step) {
  std::vector<bool> moved(s.initial.observations.size(), false);
  for (std::size_t j = 0; j < s.initial.observations.size(); ++j) {
    BaObservation& o = s.initial.observations[j];
    const Eigen::Vector3d& p = s.truth.points[o.point];
    if (p.x() < 0.5 || o.keyframe == 0) continue;  // the object: everything right of x = 0.5 m
    const Eigen::Isometry3d& T = s.truth.keyframes[o.keyframe].T_cw;
    const Eigen::Vector3d pc_true = T * p, pc_moved = T * (p + o.keyframe * step);
    const Eigen::Vector2d shift = cam.project(pc_moved) - cam.project(pc_true);
    o.obs.uv += shift;
    if (o.obs.stereo()) o.obs.u_right += shift.x() - cam.bf / pc_moved.z() + cam.bf / pc_true.z();
    moved[j] = true;
  }
  s.truth.observations = s.initial.observations;
  return moved;
}

TEST(LocalBa, ConvergesToTheTruthAndKeepsFixedKeyframes) {
  const PinholeCamera cam;
  for (KernelType kt : {KernelType::Huber, KernelType::BarronAdaptive}) {
    SyntheticBa s = small_problem(11, 4.0);  // 20 cm, 0.04 rad: far above the noise floor (~2 mm)
    const double t0 = mean_translation_error(s.initial, s.truth), r0 = mean_rotation_error(s.initial, s.truth);
    const double p0 = point_rmse(s.initial, s.truth);
    BaProblem solved = s.initial;
    const BaResult r = solve_local_ba(cam, solved, ba_config(kt));
    const double t1 = mean_translation_error(solved, s.truth), r1 = mean_rotation_error(solved, s.truth);
    const double p1 = point_rmse(solved, s.truth);
    std::printf("kernel %d: translation %.4g -> %.4g m, rotation %.4g -> %.4g rad, points %.4g -> %.4g m, "
                "cost %.4g -> %.4g, %.1f ms\n",
                static_cast<int>(kt), t0, t1, r0, r1, p0, p1, r.initial_cost, r.final_cost, 1e3 * r.seconds);
    EXPECT_LT(t1, t0 / 10);
    EXPECT_LT(r1, r0 / 10);
    EXPECT_LT(p1, p0 / 3);  // points far away are limited by the noise of their depth
    EXPECT_LT(r.final_cost, r.initial_cost / 20);
    for (std::size_t k = 0; k < s.initial.keyframes.size(); ++k) {
      if (!s.initial.keyframes[k].fixed) continue;
      EXPECT_TRUE(solved.keyframes[k].T_cw.matrix() == s.initial.keyframes[k].T_cw.matrix()) << "keyframe " << k;
    }
    int outliers = 0;
    for (bool o : r.outlier_observation) outliers += o;
    EXPECT_LT(outliers, 0.1 * static_cast<double>(r.outlier_observation.size()));  // ~5% by the 95% gate
  }
}

TEST(LocalBa, AdaptiveAlphaIsLoggedAndDropsWithOutliers) {
  const PinholeCamera cam;
  SyntheticBa clean = small_problem(5);
  SyntheticBa dirty = small_problem(5);
  add_gross_outliers(cam, dirty, 5);  // 20% wrong matches
  for (robust::AlphaFit fit : {robust::AlphaFit::ResidualNorm, robust::AlphaFit::PerComponent}) {
    BaConfig cfg = ba_config(KernelType::BarronAdaptive);
    cfg.kernel.fit = fit;
    BaProblem a = clean.initial, b = dirty.initial;
    const BaResult rc = solve_local_ba(cam, a, cfg);
    const BaResult rd = solve_local_ba(cam, b, cfg);
    ASSERT_EQ(rc.alpha_per_iteration.size(), static_cast<std::size_t>(cfg.outer_iterations + 1));
    ASSERT_EQ(rd.alpha_per_iteration.size(), rc.alpha_per_iteration.size());
    std::printf("fit %d: alpha clean", static_cast<int>(fit));
    for (double x : rc.alpha_per_iteration) std::printf(" %.1f", x);
    std::printf(" | with 20%% wrong matches");
    for (double x : rd.alpha_per_iteration) std::printf(" %.1f", x);
    std::printf("\n");
    EXPECT_EQ(rc.final_alpha, rc.alpha_per_iteration.back());
    // Converged (last outer iteration), the moving object must pull alpha well below the clean fit.
    EXPECT_LT(rd.alpha_per_iteration[cfg.outer_iterations - 1], rc.alpha_per_iteration[cfg.outer_iterations - 1] - 1.0);
    if (fit == robust::AlphaFit::PerComponent) {
      EXPECT_GT(rc.alpha_per_iteration[cfg.outer_iterations - 1], 1.5);
    }
  }
}

TEST(LocalBa, MovingObjectHurtsAdaptiveBarronLessThanHuber) {
  const PinholeCamera cam;
  double err_huber = 0, err_barron = 0;
  for (unsigned seed : {1u, 2u, 3u}) {
    SyntheticBa s = small_problem(seed);
    // A person walking 15 cm between keyframes through the right third of the scene.
    add_moving_object(cam, s, Eigen::Vector3d(0.15, 0.0, 0.0));
    BaProblem huber = s.initial, barron = s.initial;
    solve_local_ba(cam, huber, ba_config(KernelType::Huber));
    solve_local_ba(cam, barron, ba_config(KernelType::BarronAdaptive));
    err_huber += mean_translation_error(huber, s.truth);
    err_barron += mean_translation_error(barron, s.truth);
  }
  std::printf("moving object, mean keyframe translation error: Huber %.4g m, BarronAdaptive %.4g m\n", err_huber / 3,
              err_barron / 3);
  EXPECT_LT(err_barron, err_huber);
}

TEST(LocalBa, NoKernelNoGatesIsPlainLeastSquares) {
  // Guards the comparison above: plain least squares is pulled by the moving object more than Huber.
  const PinholeCamera cam;
  SyntheticBa s = small_problem(1);
  add_moving_object(cam, s, Eigen::Vector3d(0.15, 0.0, 0.0));
  BaProblem l2 = s.initial, huber = s.initial;
  BaConfig cfg = ba_config(KernelType::None);
  cfg.kernel.chi2_gates = false;
  solve_local_ba(cam, l2, cfg);
  solve_local_ba(cam, huber, ba_config(KernelType::Huber));
  EXPECT_GT(mean_translation_error(l2, s.truth), mean_translation_error(huber, s.truth));
}

TEST(LocalBa, ObservationsBehindTheCameraAreOutliers) {
  const PinholeCamera cam;
  SyntheticBa s = small_problem(3);
  // Put one point behind every free keyframe: all its observations must come out as outliers.
  s.initial.points[0] = Eigen::Vector3d(0.0, 0.0, -5.0);
  BaConfig cfg = ba_config(KernelType::Huber);
  cfg.refine_iterations = 0;  // keep the state the gate saw
  cfg.outer_iterations = 0;
  const BaResult r = solve_local_ba(cam, s.initial, cfg);
  for (std::size_t j = 0; j < s.initial.observations.size(); ++j)
    if (s.initial.observations[j].point == 0) {
      EXPECT_TRUE(r.outlier_observation[j]);
    }
}

TEST(LocalBa, RefineRunsAfterWholeBlocksLeaveTheProblem) {
  // The refine phase removes outlier residual blocks from the one Ceres problem; a point that loses every
  // observation leaves the problem (and the elimination ordering: Ceres rejects an ordering naming a block
  // the problem does not have) with them.
  const PinholeCamera cam;
  for (KernelType kt : {KernelType::Huber, KernelType::BarronAdaptive}) {
    SyntheticBa s = small_problem(3);
    s.initial.points[0] = Eigen::Vector3d(0.0, 0.0, -5.0);  // behind every keyframe: all its observations go
    BaProblem solved = s.initial;
    const BaResult r = solve_local_ba(cam, solved, ba_config(kt));
    for (std::size_t j = 0; j < solved.observations.size(); ++j)
      if (solved.observations[j].point == 0) {
        EXPECT_TRUE(r.outlier_observation[j]);  // so the point's block left the problem before the refine
      }
    EXPECT_LT(mean_translation_error(solved, s.truth), 0.5 * mean_translation_error(s.initial, s.truth));
    EXPECT_LT(r.final_cost, r.initial_cost / 5);
    EXPECT_GT(r.solver_iterations, 0);
  }
}

TEST(LocalBa, SolveFirstStartsFromTheConfiguredAlpha) {
  const PinholeCamera cam;
  SyntheticBa s = small_problem(5);
  add_gross_outliers(cam, s, 5);
  BaConfig cfg = ba_config(KernelType::BarronAdaptive);
  cfg.alpha_start = AlphaStart::SolveFirst;
  cfg.kernel.barron_alpha = 0.5;
  BaProblem solved = s.initial;
  const BaResult r = solve_local_ba(cam, solved, cfg);
  ASSERT_EQ(r.alpha_per_iteration.size(), static_cast<std::size_t>(cfg.outer_iterations + 1));
  EXPECT_EQ(r.alpha_per_iteration[0], 0.5);  // no fit before the first solve
  // The fits stay parallel to the applied alphas (local mapping indexes both with one index).
  ASSERT_EQ(r.fitted_alpha_per_iteration.size(), r.alpha_per_iteration.size());
  EXPECT_EQ(r.fitted_alpha_per_iteration[0], 0.5);
  EXPECT_LT(r.alpha_per_iteration[1], 1.0);   // fitted on the solved state: the wrong matches pull it down
  EXPECT_LT(mean_translation_error(solved, s.truth), 0.2 * mean_translation_error(s.initial, s.truth));
}

TEST(LocalBa, AnUnchangedAlphaCostsNoExtraCeresSolve) {
  // Initial state at the truth: only pixel noise, so the per-component fit finds the same alpha at every
  // checkpoint, and the alternation must go on in the same Ceres solve: no more solves than Huber's schedule.
  const PinholeCamera cam;
  SyntheticBa s = small_problem(4, 0.0);
  BaConfig cfg = ba_config(KernelType::BarronAdaptive);
  cfg.kernel.fit = robust::AlphaFit::PerComponent;
  cfg.outer_iterations = 4;
  cfg.iterations = 1;  // a checkpoint after every iteration: a restart at each would show
  BaConfig huber_cfg = cfg;
  huber_cfg.kernel.type = KernelType::Huber;
  BaProblem adaptive = s.initial, huber = s.initial;
  const BaResult ra = solve_local_ba(cam, adaptive, cfg);
  const BaResult rh = solve_local_ba(cam, huber, huber_cfg);
  ASSERT_EQ(ra.alpha_per_iteration.size(), static_cast<std::size_t>(cfg.outer_iterations + 1));
  for (int k = 1; k < cfg.outer_iterations; ++k) ASSERT_EQ(ra.alpha_per_iteration[k], ra.alpha_per_iteration[0]);
  ASSERT_GT(ra.solver_iterations, 2 * cfg.iterations);  // the solve ran past checkpoints
  EXPECT_GT(ra.solves, 0);
  EXPECT_LE(ra.solves, rh.solves);
}

TEST(LocalBa, AMovingAlphaRestartsTheSolveAtItsCheckpoint) {
  // From a perturbed start with wrong matches the fitted alpha moves between checkpoints: each move ends the
  // running Ceres solve (at most one solve per checkpoint, plus the refine), and the log keeps one alpha per
  // checkpoint.
  const PinholeCamera cam;
  SyntheticBa s = small_problem(5);
  add_gross_outliers(cam, s, 5);
  const BaConfig cfg = ba_config(KernelType::BarronAdaptive);
  BaProblem solved = s.initial;
  const BaResult r = solve_local_ba(cam, solved, cfg);
  ASSERT_EQ(r.alpha_per_iteration.size(), static_cast<std::size_t>(cfg.outer_iterations + 1));
  int moves = 0;
  for (int k = 1; k < cfg.outer_iterations; ++k) moves += r.alpha_per_iteration[k] != r.alpha_per_iteration[k - 1];
  ASSERT_GT(moves, 0);
  EXPECT_GE(r.solves, 1 + moves);
  EXPECT_LE(r.solves, cfg.outer_iterations + 1);
  EXPECT_LE(r.solver_iterations, cfg.outer_iterations * cfg.iterations + cfg.refine_iterations);
}

// A stop request (real time: a newer keyframe waits) ends the solve; the state it keeps is one the solver reached,
// so with the request standing from the start nothing moves, and the result says it was cut short.
TEST(LocalBa, AStopRequestEndsTheSolveAndSaysSo) {
  for (const BaSolver solver : {BaSolver::Schur, BaSolver::Ceres}) {
    const SyntheticBa s = small_problem(3);
    BaProblem p = s.initial;
    BaConfig cfg = ba_config(KernelType::BarronAdaptive);
    cfg.solver = solver;
    const std::atomic<bool> stop{true};
    cfg.stop = &stop;
    const BaResult r = solve_local_ba(PinholeCamera{}, p, cfg);
    EXPECT_TRUE(r.cut_short);
    EXPECT_EQ(r.solver_iterations, 0);
    EXPECT_LT(mean_translation_error(p, s.initial), 1e-12);  // poses go through a quaternion and back
    EXPECT_EQ(point_rmse(p, s.initial), 0.0);
    BaProblem q = s.initial;
    cfg.stop = nullptr;
    EXPECT_FALSE(solve_local_ba(PinholeCamera{}, q, cfg).cut_short);
    EXPECT_LT(mean_translation_error(q, s.truth), mean_translation_error(s.initial, s.truth));
  }
}

TEST(LocalBa, RejectsObservationOfMissingPoint) {
  SyntheticBa s = small_problem(3);
  s.initial.observations.push_back({0, static_cast<int>(s.initial.points.size()), {}});
  EXPECT_THROW(solve_local_ba(PinholeCamera{}, s.initial, BaConfig{}), std::invalid_argument);
}

}  // namespace
}  // namespace varslam::optim

namespace varslam::optim {
namespace {

// Free keyframe 0 lost 6 of 10 observations to the gate: reset and unflagged. Free keyframe 1 lost 1 of 10:
// kept as solved. Fixed keyframe 2 is never touched.
TEST(KeepDivergedKeyframes, ResetsOnlyFreeKeyframesLeftWithMostlyOutliers) {
  BaProblem problem;
  problem.points.resize(10);  // each seen by all three keyframes
  std::vector<Eigen::Isometry3d> before;
  for (int k = 0; k < 3; ++k) {
    Eigen::Isometry3d solved = Eigen::Isometry3d::Identity();
    solved.translation() << 1.0 + k, 0.0, 0.0;
    problem.keyframes.push_back({solved, k == 2});
    before.push_back(Eigen::Isometry3d::Identity());
  }
  std::vector<bool> outlier;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 10; ++j) {
      problem.observations.push_back({k, j, Observation{}});
      outlier.push_back((k == 0 && j < 6) || (k == 1 && j < 1) || k == 2);
    }
  const std::vector<int> reset = keep_diverged_keyframes(problem, before, outlier);
  ASSERT_EQ(reset, std::vector<int>{0});
  EXPECT_TRUE(problem.keyframes[0].T_cw.isApprox(before[0]));
  EXPECT_DOUBLE_EQ(problem.keyframes[1].T_cw.translation().x(), 2.0);
  EXPECT_DOUBLE_EQ(problem.keyframes[2].T_cw.translation().x(), 3.0);
  for (int j = 0; j < 10; ++j) EXPECT_FALSE(outlier[static_cast<std::size_t>(j)]) << j;
  EXPECT_TRUE(outlier[10]);
  EXPECT_TRUE(outlier[20]);
}

// A weak keyframe: 30 private points (seen by it alone, they move with it and are never flagged) and 10 shared
// with a fixed keyframe, 8 of them flagged. 8 of 40 is a minority, but the shared points are what hold its pose.
TEST(KeepDivergedKeyframes, ResetsAKeyframeWhoseSharedPointsAreMostlyFlagged) {
  BaProblem problem;
  problem.points.resize(40);
  Eigen::Isometry3d moved = Eigen::Isometry3d::Identity();
  moved.translation() << 1.7, 0.0, 0.0;
  problem.keyframes.push_back({moved, false});
  problem.keyframes.push_back({Eigen::Isometry3d::Identity(), true});
  const std::vector<Eigen::Isometry3d> before(2, Eigen::Isometry3d::Identity());
  std::vector<bool> outlier;
  for (int j = 0; j < 40; ++j) {
    problem.observations.push_back({0, j, Observation{}});
    outlier.push_back(j < 8);
  }
  for (int j = 0; j < 10; ++j) {
    problem.observations.push_back({1, j, Observation{}});
    outlier.push_back(false);
  }
  const KeyframeObservationCounts c = count_keyframe_observations(problem, outlier);
  EXPECT_EQ(c.total[0], 40);
  EXPECT_EQ(c.shared_total[0], 10);
  EXPECT_EQ(c.shared_flagged[0], 8);
  EXPECT_EQ(keep_diverged_keyframes(problem, before, outlier), std::vector<int>{0});
  EXPECT_TRUE(problem.keyframes[0].T_cw.isApprox(before[0]));
}

}  // namespace
}  // namespace varslam::optim
