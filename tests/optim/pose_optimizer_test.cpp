#include <gtest/gtest.h>

#include "core/geometry.hpp"
#include "optim/pose_optimizer.hpp"
#include "optim/synthetic_problems.hpp"

namespace varslam::optim {
namespace {

struct Case {
  KernelType kernel;
  PoseSolver solver;
};

class PoseOptim : public ::testing::TestWithParam<Case> {};

SyntheticPose noisy_scene_with_outliers(unsigned seed) {
  SyntheticPoseOptions opt;
  opt.observations = 500;
  opt.outlier_fraction = 0.3;
  opt.seed = seed;
  return make_synthetic_pose(PinholeCamera{}, opt);
}

TEST_P(PoseOptim, RecoversPoseWith30PercentGrossOutliersAndFlagsThem) {
  const PinholeCamera cam;
  for (unsigned seed : {1u, 2u, 3u}) {
    const SyntheticPose s = noisy_scene_with_outliers(seed);
    PoseOptimConfig cfg;
    cfg.kernel.type = GetParam().kernel;
    cfg.kernel.barron_alpha = 1.0;
    cfg.solver = GetParam().solver;
    Eigen::Isometry3d T = s.T_init;
    const PoseOptimResult r = optimize_pose(cam, T, s.points_w, s.obs, cfg);

    EXPECT_LT((T.translation() - s.T_true.translation()).norm(), 0.01) << "seed " << seed;
    EXPECT_LT(rotation_angle(T.rotation(), s.T_true.rotation()), 0.002) << "seed " << seed;
    int true_outliers = 0, flagged_outliers = 0, flagged_inliers = 0, inliers = 0;
    for (std::size_t i = 0; i < s.obs.size(); ++i) {
      true_outliers += s.is_outlier[i];
      flagged_outliers += s.is_outlier[i] && r.outlier[i];
      flagged_inliers += !s.is_outlier[i] && r.outlier[i];
      inliers += !r.outlier[i];
    }
    EXPECT_EQ(r.inliers, inliers);
    EXPECT_GT(flagged_outliers, 0.9 * true_outliers);  // most outliers caught
    // A 95% gate on true inliers rejects about 5% of them, never many more.
    EXPECT_LT(flagged_inliers, 0.1 * (static_cast<double>(s.obs.size()) - true_outliers));
  }
}

INSTANTIATE_TEST_SUITE_P(KernelsAndSolvers, PoseOptim,
                         ::testing::Values(Case{KernelType::Huber, PoseSolver::Dedicated},
                                           Case{KernelType::BarronFixed, PoseSolver::Dedicated},
                                           Case{KernelType::BarronAdaptive, PoseSolver::Dedicated},
                                           Case{KernelType::Huber, PoseSolver::Ceres},
                                           Case{KernelType::BarronFixed, PoseSolver::Ceres}));

TEST(PoseOptim, DedicatedAndCeresSolversAgree) {
  const PinholeCamera cam;
  const SyntheticPose s = noisy_scene_with_outliers(7);
  for (KernelType kt : {KernelType::Huber, KernelType::BarronFixed}) {
    PoseOptimConfig cfg;
    cfg.kernel.type = kt;
    cfg.iterations_per_round = 20;  // run both to convergence
    Eigen::Isometry3d T_dedicated = s.T_init, T_ceres = s.T_init;
    cfg.solver = PoseSolver::Dedicated;
    const PoseOptimResult a = optimize_pose(cam, T_dedicated, s.points_w, s.obs, cfg);
    cfg.solver = PoseSolver::Ceres;
    const PoseOptimResult b = optimize_pose(cam, T_ceres, s.points_w, s.obs, cfg);
    // Same optimum up to Ceres' default stopping tolerances (noise alone moves the pose by ~1e-3).
    EXPECT_LT((T_dedicated.translation() - T_ceres.translation()).norm(), 1e-4);
    EXPECT_LT(rotation_angle(T_dedicated.rotation(), T_ceres.rotation()), 1e-5);
    EXPECT_EQ(a.outlier, b.outlier);
  }
}

TEST(PoseOptim, WrongInitialOutlierFlagsAreRetestedAndComeBack) {
  const PinholeCamera cam;
  SyntheticPoseOptions opt;
  opt.outlier_fraction = 0.0;
  const SyntheticPose s = make_synthetic_pose(cam, opt);
  std::vector<bool> initial(s.obs.size(), false);
  for (std::size_t i = 0; i < initial.size(); i += 4) initial[i] = true;  // 25% wrongly flagged
  Eigen::Isometry3d T = s.T_init;
  const PoseOptimResult r = optimize_pose(cam, T, s.points_w, s.obs, PoseOptimConfig{}, &initial);
  int back = 0, flagged = 0;
  for (std::size_t i = 0; i < initial.size(); i += 4) {
    ++flagged;
    back += !r.outlier[i];
  }
  EXPECT_GT(back, 0.85 * flagged);
  EXPECT_LT((T.translation() - s.T_true.translation()).norm(), 0.01);
}

TEST(PoseOptim, WithoutGatesNothingIsExcludedButOutliersAreStillReported) {
  const PinholeCamera cam;
  const SyntheticPose s = noisy_scene_with_outliers(4);
  PoseOptimConfig cfg;
  cfg.kernel.type = KernelType::BarronFixed;
  cfg.kernel.barron_alpha = 0.0;  // Cauchy: robust enough on its own
  cfg.kernel.chi2_gates = false;
  Eigen::Isometry3d T = s.T_init;
  const PoseOptimResult r = optimize_pose(cam, T, s.points_w, s.obs, cfg);
  EXPECT_LT((T.translation() - s.T_true.translation()).norm(), 0.02);
  int caught = 0, total = 0;
  for (std::size_t i = 0; i < s.obs.size(); ++i) {
    total += s.is_outlier[i];
    caught += s.is_outlier[i] && r.outlier[i];
  }
  EXPECT_GT(caught, 0.9 * total);
}

TEST(PoseOptim, LeastSquaresIsRuinedByTheOutliers) {
  // Guards the robust tests above: without a kernel or gates the same data gives a bad pose.
  const PinholeCamera cam;
  const SyntheticPose s = noisy_scene_with_outliers(1);
  PoseOptimConfig cfg;
  cfg.kernel.type = KernelType::None;
  cfg.kernel.chi2_gates = false;
  Eigen::Isometry3d T = s.T_init;
  optimize_pose(cam, T, s.points_w, s.obs, cfg);
  EXPECT_GT((T.translation() - s.T_true.translation()).norm(), 0.02);
}

TEST(PoseOptim, RejectsMismatchedSizes) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  EXPECT_THROW(optimize_pose(PinholeCamera{}, T, {Eigen::Vector3d::UnitZ()}, {}, PoseOptimConfig{}),
               std::invalid_argument);
}

}  // namespace
}  // namespace varslam::optim
