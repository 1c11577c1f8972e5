// The sensor statistics of metrics.json (issue #33): the depth warp on scenes where the answer is known, and the
// whole section on short synthetic runs, where noisier depth must show as larger depth residuals.
#include "run/sensor_stats.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "e2e_support.hpp"

namespace varslam::slam {
namespace {

namespace fs = std::filesystem;
using run::KeyframeDepth;

// A wall parallel to the image at `z` metres, as a keyframe keeps it.
KeyframeDepth wall(double timestamp, float z, bool new_segment = false) {
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(z));
  return run::keep_keyframe_depth(timestamp, new_segment, depth);
}

Eigen::Isometry3d moved_forward(double metres) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0, 0, metres);
  return T;
}

double median(const std::vector<double>& v) { return run::percentile(v, 0.5); }

TEST(SensorStats, PercentileIsTheNearestRank) {
  EXPECT_EQ(run::percentile({}, 0.5), 0.0);
  EXPECT_EQ(run::percentile({3, 1, 2}, 0.5), 2.0);
  EXPECT_EQ(run::percentile({1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, 0.9), 9.0);
  EXPECT_EQ(run::percentile({1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, 0.95), 10.0);
}

TEST(SensorStats, AKeyframeAgreesWithItselfAndNotWithAScaledDepth) {
  const PinholeCamera cam;
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  const std::vector<double> same = run::depth_disagreement(wall(0, 2.0f), I, wall(1, 2.0f), I, cam);
  ASSERT_GT(same.size(), 10000u);  // every 4th pixel of 640 x 480 that lands in the image
  EXPECT_EQ(run::percentile(same, 1.0), 0.0);
  const std::vector<double> off = run::depth_disagreement(wall(0, 2.0f), I, wall(1, 2.04f), I, cam);
  EXPECT_NEAR(median(off), 0.04 / 2.04, 1e-4);
}

// The camera moved 0.5 m towards the wall: warped with the poses, the wall's 2 m become the 1.5 m b measures. A warp
// that applied the motion the wrong way round would predict 2.5 m.
TEST(SensorStats, TheWarpUsesThePosesBetweenTheKeyframes) {
  const PinholeCamera cam;
  const std::vector<double> d =
      run::depth_disagreement(wall(0, 2.0f), Eigen::Isometry3d::Identity(), wall(1, 1.5f), moved_forward(0.5), cam);
  ASSERT_GT(d.size(), 1000u);
  EXPECT_LT(run::percentile(d, 0.9), 1e-3);
  // Only the middle of a's image stays in b's view after moving closer.
  EXPECT_LT(d.size(), run::depth_disagreement(wall(0, 2.0f), Eigen::Isometry3d::Identity(), wall(1, 2.0f),
                                              Eigen::Isometry3d::Identity(), cam)
                          .size());
}

TEST(SensorStats, ConsistencySkipsPairsAcrossASegmentOrWithoutAPose) {
  const PinholeCamera cam;
  const std::vector<KeyframeDepth> kfs = {wall(0, 2.0f), wall(1, 2.0f), wall(2, 3.0f, true), wall(3, 3.0f),
                                          wall(4, 3.0f)};
  const Trajectory poses = {{0, Eigen::Isometry3d::Identity()},
                            {1, Eigen::Isometry3d::Identity()},
                            {2, Eigen::Isometry3d::Identity()},
                            {3, Eigen::Isometry3d::Identity()}};
  const run::DepthConsistency dc = run::depth_consistency(kfs, poses, cam);
  EXPECT_EQ(dc.pairs, 2u);  // 0-1 and 2-3: 1-2 crosses the new segment, 3-4 has no pose for 4
  EXPECT_EQ(run::percentile(dc.disagreement, 1.0), 0.0);
}

Trajectory at_identity(std::initializer_list<double> stamps) {
  Trajectory t;
  for (double s : stamps) t.push_back({s, Eigen::Isometry3d::Identity()});
  return t;
}

// Distant keyframes are compared only where their views overlap; a pose that drifted 4 cm towards the wall shows
// as the disagreement 4 cm / 2 m that neighbouring keyframes, both drifted alike, would hide.
TEST(SensorStats, LongRangeConsistencyComparesDistantOverlappingKeyframes) {
  const PinholeCamera cam;
  const std::vector<KeyframeDepth> kfs = {wall(0, 2.0f), wall(3, 2.0f), wall(10, 1.96f)};
  const run::LongRangeConsistency same = run::long_range_consistency(kfs, at_identity({0, 3, 10}), cam);
  EXPECT_EQ(same.candidates, 2u);  // 0-10 and 3-10: 0-3 are only 3 s apart
  ASSERT_EQ(same.pair_median.size(), 2u);
  EXPECT_NEAR(same.pair_median[0], 0.04 / 1.96, 1e-3);  // the poses say the wall stayed where it was

  Trajectory drifted = at_identity({0, 3, 10});
  drifted[2].T_wc = moved_forward(0.04);  // the pose that explains the nearer wall
  const run::LongRangeConsistency fixed = run::long_range_consistency(kfs, drifted, cam);
  ASSERT_EQ(fixed.pair_median.size(), 2u);
  EXPECT_LT(fixed.pair_median[0], 1e-3);

  Trajectory turned = at_identity({0, 3, 10});
  turned[2].T_wc.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_EQ(run::long_range_consistency(kfs, turned, cam).candidates, 0u);  // looking another way

  // Another surface (3 m where 2 m was seen): no overlap, so the pair is a candidate but not compared.
  const run::LongRangeConsistency other =
      run::long_range_consistency({wall(0, 2.0f), wall(10, 3.0f)}, at_identity({0, 10}), cam);
  EXPECT_EQ(other.candidates, 1u);
  EXPECT_TRUE(other.pair_median.empty());

  run::DistantPairs one;
  one.max_pairs = 1;
  EXPECT_EQ(run::long_range_consistency(kfs, at_identity({0, 3, 10}), cam, one).pair_median.size(), 1u);
}

TEST(SensorStats, TheTableShowsEachRunAndADashWhereANumberIsMissing) {
  const nlohmann::json a = {{"reprojection_px", {{"median", 0.5}, {"p95", 1.25}}},
                            {"depth_residual_m", {{"median", 0.002}}}};
  const nlohmann::json b = {{"reprojection_px", {{"median", 0.75}}}};
  const std::string t = run::sensor_table_markdown({"real", "synth"}, {a, b});
  EXPECT_NE(t.find("| statistic | real | synth |"), std::string::npos) << t;
  EXPECT_NE(t.find("median (px) | 0.500 | 0.750 |"), std::string::npos) << t;
  EXPECT_NE(t.find("p95 (px) | 1.250 | - |"), std::string::npos) << t;
  EXPECT_NE(t.find("median (mm) | 2.00 | - |"), std::string::npos) << t;
  // Every row has its three cells: no label breaks the table with a '|' of its own.
  std::istringstream lines(t);
  for (std::string line; std::getline(lines, line);) EXPECT_EQ(std::count(line.begin(), line.end(), '|'), 4) << line;
}

nlohmann::json sensor_of_run(bool depth_noise, const std::string& name) {
  const fs::path out = fs::temp_directory_path() / ("varslam_sensor_stats_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const run::RunSummary s = e2e::run_on(e2e::static_4s_sequence(depth_noise), out, RunMode::Deterministic);
  EXPECT_EQ(s.tracked, s.frames);
  fs::remove_all(out);
  nlohmann::json sensor = s.metrics.at("sensor");
  sensor["keyframes"] = s.keyframes;  // of the final map, for the pair count
  return sensor;
}

TEST(SensorStats, EveryRunReportsSaneSensorStatistics) {
  const nlohmann::json s = sensor_of_run(true, "noisy");
  EXPECT_GT(s["depth_share"]["median"].get<double>(), 0.5);
  EXPECT_LE(s["depth_share"]["median"].get<double>(), 1.0);
  EXPECT_EQ(s["depth_share"]["frames"].get<std::size_t>(), 120u);

  const auto& px = s["reprojection_px"];
  EXPECT_GT(px["observations"].get<std::size_t>(), 119u * 100u);  // every frame after the first, hundreds of inliers
  EXPECT_EQ(px["frames"].get<std::size_t>(), 119u);               // the first frame is not solved, it starts the map
  EXPECT_GT(px["median"].get<double>(), 0.05);
  EXPECT_LT(px["median"].get<double>(), 2.0);
  EXPECT_GE(px["p95"].get<double>(), px["median"].get<double>());

  const auto& dz = s["depth_residual_m"];
  // The generator's noise, sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2 m, is ~2.6 cm at the room's 4 m: the residual
  // (noise of the measurement and of the point built from an earlier one) is of that order, and / z^2 near 0.0019.
  EXPECT_GT(dz["median"].get<double>(), 0.002);
  EXPECT_LT(dz["median"].get<double>(), 0.06);
  EXPECT_GE(dz["p95"].get<double>(), dz["median"].get<double>());
  EXPECT_GT(s["depth_residual_over_z2"]["median"].get<double>(), 0.0003);
  EXPECT_LT(s["depth_residual_over_z2"]["median"].get<double>(), 0.006);

  const auto& tl = s["track_length"];
  EXPECT_GE(tl["median"].get<double>(), 2.0);  // a static scene: points seen from several keyframes
  EXPECT_GE(tl["p90"].get<double>(), tl["median"].get<double>());
  EXPECT_GT(tl["points"].get<std::size_t>(), 100u);

  const auto& dc = s["depth_consistency"];
  // One segment, every keyframe tracked: each keyframe of the final map but the first pairs with the one before it
  // (culled keyframes pair too).
  EXPECT_GE(s["keyframes"].get<std::size_t>(), 3u);
  EXPECT_GE(dc["pairs"].get<std::size_t>(), s["keyframes"].get<std::size_t>() - 1);
  EXPECT_GT(dc["pixels"].get<std::size_t>(), 1000u);
  EXPECT_LT(dc["median"].get<double>(), 0.05);  // a static room at good poses agrees with itself within a few %
  EXPECT_GE(dc["p90"].get<double>(), dc["median"].get<double>());
  // 4 s: no keyframes 5 s apart; the ground truth's reference is there (a sequence with ground truth).
  EXPECT_EQ(s["long_range_consistency"]["candidates"].get<std::size_t>(), 0u);
  EXPECT_EQ(s["long_range_consistency_groundtruth"]["pairs"].get<std::size_t>(), 0u);
}

TEST(SensorStats, NoisierDepthGivesLargerDepthResiduals) {
  const nlohmann::json clean = sensor_of_run(false, "clean");
  const nlohmann::json noisy = sensor_of_run(true, "noisy2");
  const double clean_dz = clean["depth_residual_m"]["median"].get<double>();
  const double noisy_dz = noisy["depth_residual_m"]["median"].get<double>();
  EXPECT_LT(3.0 * clean_dz, noisy_dz) << "clean " << clean_dz << " m, noisy " << noisy_dz << " m";
  EXPECT_LT(clean["depth_consistency"]["median"].get<double>(), noisy["depth_consistency"]["median"].get<double>());
}

}  // namespace
}  // namespace varslam::slam

// A long run keeps a bounded sample of its residuals: uniform (its percentiles are the stream's), and the same
// stream gives the same sample.
TEST(SensorStats, TheResidualSampleIsBoundedUniformAndRepeatable) {
  varslam::run::SampleReservoir a(1000), b(1000);
  for (int i = 0; i < 100000; ++i) {
    a.add(i % 1000);
    b.add(i % 1000);
  }
  EXPECT_EQ(a.values().size(), 1000u);
  EXPECT_EQ(a.seen(), 100000u);
  EXPECT_EQ(a.values(), b.values());
  std::vector<double> v = a.values();
  std::sort(v.begin(), v.end());
  EXPECT_NEAR(v[500], 500.0, 60.0);
  EXPECT_NEAR(v[950], 950.0, 30.0);
}
