// Association, alignment and ATE statistics on constructed data with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.hpp"
#include "eval/ate.hpp"
#include "eval_test_util.hpp"

namespace varslam {
namespace {

Trajectory stamps_only(std::initializer_list<double> stamps) {
  Trajectory t;
  for (double s : stamps) t.push_back({s, Eigen::Isometry3d::Identity()});
  return t;
}

TEST(Association, TakesClosestPairsGreedilyAndOneToOne) {
  // Estimate 1.005 is within reach of gt 1.00 and 1.01; gt 1.01 is nearer, so gt 1.00 takes 0.995 instead.
  const Trajectory gt = stamps_only({1.00, 1.01, 2.00});
  const Trajectory est = stamps_only({0.995, 1.009, 3.0});
  const auto m = associate_timestamps(gt, est);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].first, 0u);
  EXPECT_EQ(m[0].second, 0u);
  EXPECT_EQ(m[1].first, 1u);
  EXPECT_EQ(m[1].second, 1u);
}

TEST(Association, GreedyOrderCanLeaveAPoseUnmatched) {
  // gt 1.000 and 1.015; est 1.010. |1.015-1.010| = 0.005 wins over 0.010: gt 1.000 stays unmatched even
  // though it has a partner in reach (one-to-one).
  const auto m = associate_timestamps(stamps_only({1.000, 1.015}), stamps_only({1.010}));
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].first, 1u);
  EXPECT_EQ(m[0].second, 0u);
}

TEST(Association, MaxDifferenceIsStrict) {
  const Trajectory gt = stamps_only({10.0, 20.0});
  const Trajectory est = stamps_only({10.0 + 0.25, 20.0 + 0.125});  // exact binary fractions
  EXPECT_EQ(associate_timestamps(gt, est, {0.0, 0.25}).size(), 1u);   // 0.25 is not < 0.25
  EXPECT_EQ(associate_timestamps(gt, est, {0.0, 0.2500001}).size(), 2u);
  EXPECT_TRUE(associate_timestamps(gt, est, {0.0, 0.1}).empty());
}

TEST(Association, OffsetShiftsTheSecondTrajectory) {
  const Trajectory gt = stamps_only({5.0, 6.0, 7.0});
  const Trajectory est = stamps_only({4.5, 5.5, 6.5});
  EXPECT_TRUE(associate_timestamps(gt, est).empty());
  const auto m = associate_timestamps(gt, est, {0.5, 0.02});
  ASSERT_EQ(m.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(m[k].second, k);
}

TEST(Association, UnsortedInputGivesTimeSortedIndices) {
  const Trajectory gt = stamps_only({3.0, 1.0, 2.0});
  const Trajectory est = stamps_only({2.001, 3.001, 1.001});
  const auto m = associate_timestamps(gt, est);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0].first, 1u);  // t = 1
  EXPECT_EQ(m[0].second, 2u);
  EXPECT_EQ(m[1].first, 2u);  // t = 2
  EXPECT_EQ(m[1].second, 0u);
  EXPECT_EQ(m[2].first, 0u);  // t = 3
  EXPECT_EQ(m[2].second, 1u);
}

TEST(Association, RepeatedTimestampKeepsTheLaterPose) {
  const Trajectory gt = stamps_only({1.0, 1.0, 2.0});
  const auto m = associate_timestamps(gt, stamps_only({1.0, 2.0}));
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].first, 1u);
}

TEST(Association, EmptyInputsGiveNoMatches) {
  EXPECT_TRUE(associate_timestamps({}, stamps_only({1.0})).empty());
  EXPECT_TRUE(associate_timestamps(stamps_only({1.0}), {}).empty());
}

TEST(NearestTimestamp, PicksTheClosestAndClampsAtTheEnds) {
  const std::vector<double> s{1.0, 2.0, 4.0};
  EXPECT_EQ(nearest_timestamp_index(s, -5.0), 0u);
  EXPECT_EQ(nearest_timestamp_index(s, 1.4), 0u);
  EXPECT_EQ(nearest_timestamp_index(s, 1.6), 1u);
  EXPECT_EQ(nearest_timestamp_index(s, 3.1), 2u);
  EXPECT_EQ(nearest_timestamp_index(s, 9.0), 2u);
  EXPECT_EQ(nearest_timestamp_index(s, 3.0), 1u);  // tie: the earlier
}

Eigen::Matrix3Xd random_points(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  Eigen::Matrix3Xd p(3, n);
  for (int k = 0; k < n; ++k) p.col(k) = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return p;
}

TEST(Alignment, RecoversAKnownRigidTransformExactly) {
  const Eigen::Matrix3Xd model = random_points(50, 1);
  const Eigen::Isometry3d T = test::pose({0.3, -1.2, 2.5}, {0.4, -0.9, 1.7});
  const Eigen::Matrix3Xd data = (T.linear() * model).colwise() + T.translation();
  const Alignment a = align_point_sets(model, data);
  EXPECT_TRUE(a.R.isApprox(T.linear(), 1e-12));
  EXPECT_TRUE(a.t.isApprox(T.translation(), 1e-12));
  EXPECT_DOUBLE_EQ(a.scale, 1.0);
  for (int k = 0; k < model.cols(); ++k) EXPECT_LT((a.apply(Eigen::Vector3d(model.col(k))) - data.col(k)).norm(), 1e-12);
}

TEST(Alignment, NeverReturnsAReflection) {
  // Mirrored data: the best proper rotation, not the mirror, must come back.
  const Eigen::Matrix3Xd model = random_points(30, 2);
  Eigen::Matrix3Xd data = model;
  data.row(2) *= -1.0;
  const Alignment a = align_point_sets(model, data);
  EXPECT_NEAR(a.R.determinant(), 1.0, 1e-12);
  EXPECT_NEAR((a.R * a.R.transpose() - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
}

TEST(Alignment, WithScaleRecoversASimilarity) {
  const Eigen::Matrix3Xd model = random_points(40, 3);
  const Eigen::Isometry3d T = test::pose({-0.5, 0.1, 0.9}, {1.1, 0.2, -0.3});
  const double s = 2.75;
  const Eigen::Matrix3Xd data = (s * T.linear() * model).colwise() + T.translation();
  const Alignment sim = align_point_sets(model, data, true);
  EXPECT_NEAR(sim.scale, s, 1e-12);
  EXPECT_TRUE(sim.R.isApprox(T.linear(), 1e-12));
  EXPECT_TRUE(sim.t.isApprox(T.translation(), 1e-12));
  // The rigid alignment cannot absorb the scale: it leaves a residual.
  const Alignment rigid = align_point_sets(model, data, false);
  EXPECT_DOUBLE_EQ(rigid.scale, 1.0);
  EXPECT_GT(((rigid.R * model).colwise() + rigid.t - data).norm(), 1.0);
}

TEST(Alignment, RejectsBadInput) {
  EXPECT_THROW(align_point_sets(Eigen::Matrix3Xd(3, 1), Eigen::Matrix3Xd(3, 1)), std::invalid_argument);
  EXPECT_THROW(align_point_sets(Eigen::Matrix3Xd(3, 4), Eigen::Matrix3Xd(3, 5)), std::invalid_argument);
}

TEST(ErrorStatistics, MatchesNumpyConventions) {
  const auto s = compute_error_statistics({3.0, 1.0, 4.0, 2.0});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);                  // even count: mean of the two middle values
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));         // population std (ddof = 0)
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4.0));
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(compute_error_statistics({5.0, 1.0, 3.0}).median, 3.0);
  EXPECT_EQ(compute_error_statistics({}).count, 0u);
}

TEST(Ate, RigidlyMovedCopyHasZeroError) {
  Trajectory gt;
  Trajectory est;
  const Eigen::Isometry3d T = test::pose({1.0, 2.0, -0.5}, {0.1, 0.7, -0.2});
  for (int k = 0; k < 100; ++k) {
    const double t = 0.03 * k;
    const Eigen::Isometry3d P = test::pose({std::sin(t), std::cos(2 * t), 0.3 * t}, {0.0, 0.1 * t, 0.0});
    gt.push_back({t, P});
    est.push_back({t + 0.004, T * P});  // other frame, small time offset
  }
  const AteResult r = evaluate_ate(gt, est);
  EXPECT_EQ(r.stats.count, 100u);
  EXPECT_LT(r.stats.rmse, 1e-12);
  EXPECT_LT(r.stats.max, 1e-12);
  EXPECT_TRUE(r.alignment.R.isApprox(T.linear().transpose(), 1e-9));
  // The aligned estimate lands on the ground truth, orientation included.
  for (std::size_t k = 0; k < gt.size(); ++k) {
    EXPECT_TRUE(r.aligned_estimate[k].T_wc.isApprox(gt[k].T_wc, 1e-9));
  }
  EXPECT_DOUBLE_EQ(r.pairs[3].gt_timestamp, gt[3].timestamp);
  EXPECT_DOUBLE_EQ(r.pairs[3].est_timestamp, est[3].timestamp);
}

TEST(Ate, ScaledCopyGivesKnownErrorsRigidlyAndNoneWithScale) {
  // Estimate = ground truth scaled by 1.1 about its centroid: the rigid fit is the identity (the cross-
  // covariance is symmetric positive definite), so each error is 0.1 * distance to the centroid; the Sim(3)
  // fit undoes the scale exactly.
  Trajectory gt;
  Trajectory est;
  const Eigen::Vector3d c(0.5, -0.25, 1.0);
  const std::vector<Eigen::Vector3d> offsets{{1, 0, 0}, {-1, 0, 0}, {0, 2, 0}, {0, -2, 0}, {0, 0, 3}, {0, 0, -3}};
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    gt.push_back({double(k), test::pose(c + offsets[k])});
    est.push_back({double(k), test::pose(c + 1.1 * offsets[k])});
  }
  const AteResult rigid = evaluate_ate(gt, est);
  EXPECT_TRUE(rigid.alignment.R.isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_NEAR(rigid.stats.min, 0.1, 1e-12);
  EXPECT_NEAR(rigid.stats.max, 0.3, 1e-12);
  EXPECT_NEAR(rigid.stats.mean, 0.2, 1e-12);
  EXPECT_NEAR(rigid.stats.median, 0.2, 1e-12);
  EXPECT_NEAR(rigid.stats.rmse, std::sqrt((0.01 + 0.04 + 0.09) * 2 / 6), 1e-12);
  EXPECT_NEAR(rigid.stats.std, std::sqrt(2.0 * (0.01 + 0.0 + 0.01) / 6), 1e-12);
  EXPECT_NEAR(rigid.pairs[4].error, 0.3, 1e-12);

  AteOptions with_scale;
  with_scale.with_scale = true;
  const AteResult sim = evaluate_ate(gt, est, with_scale);
  EXPECT_NEAR(sim.alignment.scale, 1.0 / 1.1, 1e-12);
  EXPECT_LT(sim.stats.max, 1e-12);
}

TEST(Ate, AFixedAlignmentShowsAConsistentOffsetThatAFreshOneHides) {
  Trajectory gt, est;
  for (int i = 0; i < 10; ++i) {
    StampedPose p;
    p.timestamp = i * 0.1;
    p.T_wc.translation() = Eigen::Vector3d(0.1 * i, 0.02 * i * i, 0);
    gt.push_back(p);
    p.T_wc.translation() += Eigen::Vector3d(0.05, 0, 0);  // sits 5 cm off, every frame
    est.push_back(p);
  }
  EXPECT_LT(evaluate_ate(gt, est).stats.max, 1e-9);
  AteOptions in_map;
  in_map.fixed_alignment = Alignment{};  // the map frame is the ground-truth frame
  const AteResult r = evaluate_ate(gt, est, in_map);
  EXPECT_NEAR(r.stats.rmse, 0.05, 1e-9);
  EXPECT_NEAR(r.stats.min, 0.05, 1e-9);
}

TEST(Ate, TooFewMatchesIsAnInputError) {
  EXPECT_THROW(evaluate_ate(stamps_only({1.0, 2.0}), stamps_only({1.0, 5.0})), InputError);
}

TEST(CorrectRate, IsPairsOverFrames) {
  EXPECT_DOUBLE_EQ(correct_rate(45, 50), 0.9);
  EXPECT_DOUBLE_EQ(correct_rate(3, 0), 0.0);
  EXPECT_DOUBLE_EQ(correct_rate(60, 50), 1.0);
  const Trajectory gt = stamps_only({1.0, 2.0, 3.0});
  EXPECT_EQ(count_frames_with_ground_truth({0.5, 1.01, 2.0, 2.5, 2.99, 9.0}, gt), 3u);
}

}  // namespace
}  // namespace varslam
