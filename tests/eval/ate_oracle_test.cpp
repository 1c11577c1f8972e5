// ATE of the published reference estimates against TUM / Bonn ground truth must reproduce the TUM
// benchmark's evaluate_ate numbers (listed in ../shared/trajectories/README.md): the brief asks for 1e-4 m;
// the test holds them to the README's printed precision (6 decimals), every statistic and the pair count.
#include <gtest/gtest.h>

#include <filesystem>

#include "eval/ate.hpp"
#include "eval_test_util.hpp"

namespace varslam {
namespace {

struct Oracle {
  const char* folder;
  std::size_t pairs;
  double rmse, mean, median, std, min, max;
};

class AteOracle : public ::testing::TestWithParam<Oracle> {};

TEST_P(AteOracle, MatchesTumEvaluateAte) {
  const Oracle& o = GetParam();
  const auto dir = test::shared_trajectories() / o.folder;
  if (!std::filesystem::exists(dir / "groundtruth.txt")) {
    GTEST_SKIP() << "shared data not found at " << dir << " (set VARSLAM_SHARED_DIR when configuring)";
  }
  const Trajectory gt = test::read_tum(dir / "groundtruth.txt");
  const Trajectory est = test::read_tum(dir / "reference_estimate_CameraTrajectory.txt");
  const AteResult r = evaluate_ate(gt, est);
  // The README values are printed with 6 decimals: agreeing to rounding means the same computation.
  constexpr double kPrinted = 0.6e-6;
  EXPECT_EQ(r.stats.count, o.pairs);
  EXPECT_EQ(r.pairs.size(), o.pairs);
  EXPECT_NEAR(r.stats.rmse, o.rmse, kPrinted);
  EXPECT_NEAR(r.stats.mean, o.mean, kPrinted);
  EXPECT_NEAR(r.stats.median, o.median, kPrinted);
  EXPECT_NEAR(r.stats.std, o.std, kPrinted);
  EXPECT_NEAR(r.stats.min, o.min, kPrinted);
  EXPECT_NEAR(r.stats.max, o.max, kPrinted);
  EXPECT_EQ(r.aligned_estimate.size(), est.size());
  EXPECT_NEAR(r.alignment.scale, 1.0, 0.0);
  EXPECT_NEAR(r.alignment.R.determinant(), 1.0, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(
    SharedTrajectories, AteOracle,
    ::testing::Values(
        Oracle{"rgbd_dataset_freiburg1_desk", 573, 0.019860, 0.017162, 0.014373, 0.009994, 0.001853, 0.055719},
        Oracle{"rgbd_dataset_freiburg1_360", 744, 0.176025, 0.157179, 0.146151, 0.079245, 0.017138, 0.408156},
        Oracle{"rgbd_dataset_freiburg2_desk_with_person", 3631, 0.016855, 0.015815, 0.015987, 0.005830, 0.001263,
               0.074147},
        Oracle{"rgbd_dataset_freiburg3_sitting_static", 676, 0.010113, 0.008910, 0.008372, 0.004783, 0.000261,
               0.046647},
        Oracle{"rgbd_bonn_balloon", 438, 0.081345, 0.071832, 0.072144, 0.038172, 0.007083, 0.178602},
        Oracle{"rgbd_bonn_crowd3", 838, 0.388603, 0.283550, 0.186569, 0.265728, 0.026725, 1.330453}),
    [](const ::testing::TestParamInfo<Oracle>& param_info) {
      std::string name = param_info.param.folder;
      for (auto& c : name) {
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      }
      return name;
    });

}  // namespace
}  // namespace varslam
