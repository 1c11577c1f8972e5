// RPE on constructed trajectories whose drift per second is known.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "eval/rpe.hpp"
#include "eval_test_util.hpp"

namespace varslam {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Ground truth at 100 Hz over [-0.5, 10.5] s; estimate at 10 Hz over [0, 10] s (101 poses).
template <class GtPose, class EstPose>
void make(Trajectory& gt, Trajectory& est, GtPose gt_pose, EstPose est_pose) {
  for (int k = -50; k <= 1050; ++k) gt.push_back({0.01 * k, gt_pose(0.01 * k)});
  for (int k = 0; k <= 100; ++k) est.push_back({0.1 * k, est_pose(0.1 * k)});
}

TEST(Rpe, ConstantSpeedDriftGivesKnownTranslationError) {
  Trajectory gt;
  Trajectory est;
  // The estimate moves 10 % faster: 0.1 m of error per second, no rotation error.
  make(gt, est, [](double t) { return test::pose({t, 0, 0}); }, [](double t) { return test::pose({1.1 * t, 0, 0}); });
  const RpeResult r = evaluate_rpe(gt, est);
  // i = 0..89 pair with j = i + 10; pairs ending at the last estimate pose are dropped, as in evaluate_rpe.
  ASSERT_EQ(r.pairs.size(), 90u);
  EXPECT_NEAR(r.translation.rmse, 0.1, 1e-9);
  EXPECT_NEAR(r.translation.mean, 0.1, 1e-9);
  EXPECT_NEAR(r.translation.median, 0.1, 1e-9);
  EXPECT_NEAR(r.translation.max, 0.1, 1e-9);
  EXPECT_NEAR(r.rotation_deg.max, 0.0, 1e-6);
  EXPECT_NEAR(r.pairs.front().est_t1 - r.pairs.front().est_t0, 1.0, 1e-9);
  EXPECT_NEAR(r.pairs.front().gt_t1 - r.pairs.front().gt_t0, 1.0, 1e-9);
}

TEST(Rpe, ConstantYawDriftGivesKnownRotationError) {
  Trajectory gt;
  Trajectory est;
  // Turning on the spot at 10 deg/s; the estimate turns at 12 deg/s: 2 degrees of error per second.
  make(gt, est, [](double t) { return test::pose({0, 0, 0}, {0, 0, 10 * kDeg * t}); },
       [](double t) { return test::pose({0, 0, 0}, {0, 0, 12 * kDeg * t}); });
  const RpeResult r = evaluate_rpe(gt, est);
  ASSERT_EQ(r.pairs.size(), 90u);
  EXPECT_NEAR(r.rotation_deg.rmse, 2.0, 1e-6);
  EXPECT_NEAR(r.rotation_deg.mean, 2.0, 1e-6);
  EXPECT_NEAR(r.rotation_deg.min, 2.0, 1e-6);
  EXPECT_NEAR(r.translation.max, 0.0, 1e-9);
}

TEST(Rpe, PerfectEstimateInAnotherFrameHasNoError) {
  Trajectory gt;
  Trajectory est;
  const Eigen::Isometry3d T = test::pose({3, -1, 2}, {0.3, 0.2, 1.0});
  auto motion = [](double t) { return test::pose({std::sin(t), 0.5 * t, std::cos(0.5 * t)}, {0.1 * t, 0.2, -0.05 * t}); };
  make(gt, est, motion, [&](double t) { return Eigen::Isometry3d(T * motion(t)); });
  const RpeResult r = evaluate_rpe(gt, est);
  EXPECT_LT(r.translation.max, 1e-9);
  EXPECT_LT(r.rotation_deg.max, 1e-5);
}

TEST(Rpe, ScaleOptionRescalesTheEstimate) {
  Trajectory gt;
  Trajectory est;
  // A monocular-like estimate at half scale is perfect once scaled by 2.
  make(gt, est, [](double t) { return test::pose({t, 0.2 * t, 0}); }, [](double t) { return test::pose({0.5 * t, 0.1 * t, 0}); });
  EXPECT_GT(evaluate_rpe(gt, est).translation.rmse, 0.4);
  EXPECT_LT(evaluate_rpe(gt, est, {1.0, 0.0, 2.0}).translation.max, 1e-9);
}

TEST(Rpe, PairsWithoutNearbyGroundTruthAreSkipped) {
  Trajectory gt;
  Trajectory est;
  make(gt, est, [](double t) { return test::pose({t, 0, 0}); }, [](double t) { return test::pose({t, 0, 0}); });
  // Remove ground truth over [4, 6] s: estimate poses in (4, 6) are then more than 2 median ground-truth
  // intervals (0.02 s) from any ground truth, so pairs touching them are dropped; 4.0 and 6.0 still have
  // ground truth 0.01 s away and stay.
  std::erase_if(gt, [](const StampedPose& p) { return p.timestamp > 3.995 && p.timestamp < 6.005; });
  const RpeResult r = evaluate_rpe(gt, est);
  for (const auto& p : r.pairs) {
    EXPECT_FALSE(p.est_t0 > 4.05 && p.est_t0 < 5.95) << p.est_t0;
    EXPECT_FALSE(p.est_t1 > 4.05 && p.est_t1 < 5.95) << p.est_t1;
  }
  // i = 0..89 minus those with t_i or t_i + 1 in {4.1, ..., 5.9}: t_i in [3.1, 5.9] (29 values).
  EXPECT_EQ(r.pairs.size(), 90u - 29u);
}

TEST(Rpe, TrackingGapNeverPairsAPoseWithItself) {
  Trajectory gt;
  Trajectory est;
  make(gt, est, [](double t) { return test::pose({t, 0, 0}); }, [](double t) { return test::pose({1.1 * t, 0, 0}); });
  // Tracking lost over (3, 6.5) s: for t_i just before the gap, t_i + 1 is nearer to t_i than to 6.5.
  std::erase_if(est, [](const StampedPose& p) { return p.timestamp > 3.05 && p.timestamp < 6.45; });
  const RpeResult r = evaluate_rpe(gt, est);
  // Pairs just before the gap span less than a second (as in the tool), but never zero; each carries the
  // 0.1 m/s drift over its own span.
  for (const auto& p : r.pairs) {
    EXPECT_GT(p.est_t1, p.est_t0 + 0.05);
    EXPECT_NEAR(p.translation_error, 0.1 * (p.est_t1 - p.est_t0), 1e-9);
  }
  EXPECT_GT(r.translation.min, 0.0099);
}

TEST(Rpe, DisjointTrajectoriesAreAnInputError) {
  Trajectory gt;
  Trajectory est;
  for (int k = 0; k < 100; ++k) gt.push_back({0.01 * k, test::pose({0, 0, 0})});
  for (int k = 0; k < 50; ++k) est.push_back({100.0 + 0.1 * k, test::pose({0, 0, 0})});
  EXPECT_THROW(evaluate_rpe(gt, est), InputError);
  EXPECT_THROW(evaluate_rpe({}, est), InputError);
}

}  // namespace
}  // namespace varslam
