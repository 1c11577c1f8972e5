#include <gtest/gtest.h>

#include <random>

#include "optim/local_ba.hpp"
#include "optim/synthetic_problems.hpp"

namespace varslam::optim {
namespace {

SyntheticBa problem(unsigned seed, double outlier_share) {
  SyntheticBaOptions opt;
  opt.keyframes = 8;
  opt.fixed_keyframes = 2;
  opt.points = 400;
  opt.observe_probability = 0.7;
  opt.seed = seed;
  SyntheticBa s = make_synthetic_ba(PinholeCamera{}, opt);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (BaObservation& o : s.initial.observations)
    if (u01(rng) < outlier_share) o.obs.uv += Eigen::Vector2d(40.0 * u01(rng) - 20.0, 40.0 * u01(rng) - 20.0);
  return s;
}

BaResult solve(BaProblem& p, KernelType kernel, BaSolver solver) {
  BaConfig cfg;
  cfg.kernel.type = kernel;
  cfg.kernel.barron_alpha = kernel == KernelType::BarronFixed ? -2.0 : 1.0;
  cfg.solver = solver;
  return solve_local_ba(PinholeCamera{}, p, cfg);
}

class SchurAgainstCeres : public ::testing::TestWithParam<KernelType> {};

// The dedicated solver replaces Ceres' sparse Schur solver with the same step control: on the same problem both
// reach the same poses, points, outlier flags and (for the adaptive kernel) the same alphas.
TEST_P(SchurAgainstCeres, ReachTheSameSolution) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const SyntheticBa s = problem(seed, 0.1);
    BaProblem dedicated = s.initial, ceres = s.initial;
    const BaResult a = solve(dedicated, GetParam(), BaSolver::Schur);
    const BaResult b = solve(ceres, GetParam(), BaSolver::Ceres);
    EXPECT_LT(mean_translation_error(dedicated, ceres), 1e-5) << "seed " << seed;
    EXPECT_LT(mean_rotation_error(dedicated, ceres), 1e-6) << "seed " << seed;
    EXPECT_LT(point_rmse(dedicated, ceres), 1e-4) << "seed " << seed;
    EXPECT_EQ(a.outlier_observation, b.outlier_observation) << "seed " << seed;
    ASSERT_EQ(a.alpha_per_iteration.size(), b.alpha_per_iteration.size());
    for (std::size_t i = 0; i < a.alpha_per_iteration.size(); ++i)
      EXPECT_NEAR(a.alpha_per_iteration[i], b.alpha_per_iteration[i], 1e-9);
    EXPECT_NEAR(a.final_cost, b.final_cost, 1e-6 * b.final_cost + 1e-9);
    // And both got closer to the truth than the start was.
    EXPECT_LT(mean_translation_error(dedicated, s.truth), mean_translation_error(s.initial, s.truth));
  }
}

INSTANTIATE_TEST_SUITE_P(Kernels, SchurAgainstCeres,
                         ::testing::Values(KernelType::None, KernelType::Huber, KernelType::BarronFixed,
                                           KernelType::BarronAdaptive));

// No pose variable at all (every keyframe fixed): the reduced system is empty and the points still move as Ceres
// moves them.
TEST(SchurLm, OnlyFixedKeyframesStillRefinesThePoints) {
  SyntheticBa s = problem(4, 0.0);
  for (BaKeyframe& k : s.initial.keyframes) k.fixed = true;
  for (std::size_t k = 0; k < s.initial.keyframes.size(); ++k) s.initial.keyframes[k].T_cw = s.truth.keyframes[k].T_cw;
  BaProblem p = s.initial, c = s.initial;
  const BaResult r = solve(p, KernelType::Huber, BaSolver::Schur);
  solve(c, KernelType::Huber, BaSolver::Ceres);
  EXPECT_LT(point_rmse(p, c), 1e-6);
  EXPECT_GT(r.solver_iterations, 0);
  EXPECT_LT(r.final_cost, 0.5 * r.initial_cost);
  for (std::size_t k = 0; k < p.keyframes.size(); ++k)
    EXPECT_TRUE(p.keyframes[k].T_cw.isApprox(s.truth.keyframes[k].T_cw, 1e-12));
}

}  // namespace
}  // namespace varslam::optim
