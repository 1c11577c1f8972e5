// The whole pipeline on short sequences: synthetic (always) and the real 7-Scenes excerpt (when ../shared
// is present). Bounds are loose enough for noise, tight enough that a broken tracker fails them.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <unistd.h>

#include "e2e_support.hpp"
#include "io/trajectory_io.hpp"
#include "file_text.hpp"

namespace varslam::slam {
namespace {

namespace fs = std::filesystem;
using run::RunOptions;
using run::RunSummary;
using run::run_slam;
using e2e::cached_sequence;
using e2e::run_on;
using e2e::static_4s_sequence;

using test::slurp;

fs::path test_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("varslam_e2e_" + name);
  fs::remove_all(d);
  return d;
}

// A synthetic sequence along one of the real camera paths in ../shared/trajectories, cached under `name`;
// empty when ../shared is absent.
fs::path path_sequence(const std::string& name, const std::string& path_name, const std::string& scenario,
                       double seconds, std::uint64_t seed, double path_start,
                       const synth::RealSensorEffects& real = {}) {
  const fs::path path = fs::path(VARSLAM_SHARED_DIR) / "trajectories" / path_name;
  if (!fs::exists(path)) return {};
  synth::SynthConfig cfg;
  cfg.scenario = scenario;
  cfg.seconds = seconds;
  cfg.seed = seed;
  cfg.path_file = path;
  cfg.path_start = path_start;
  cfg.real = real;
  return cached_sequence(name, cfg);
}

void expect_tracked_with_ate_below(const RunSummary& s, double bound_m) {
  EXPECT_EQ(s.tracked, s.frames);
  ASSERT_TRUE(s.ate_rmse.has_value());
  EXPECT_LT(*s.ate_rmse, bound_m) << "ATE RMSE " << *s.ate_rmse << " m";
}

TEST(EndToEnd, StaticSyntheticSceneIsTrackedAccurately) {
  const RunSummary s = run_on(static_4s_sequence(), test_dir("static_run"), RunMode::Deterministic);
  EXPECT_EQ(s.lost, 0u);
  EXPECT_EQ(s.tracked, s.frames);
  ASSERT_TRUE(s.ate_rmse.has_value());
  EXPECT_LT(*s.ate_rmse, 0.02) << "ATE RMSE " << *s.ate_rmse << " m";
  EXPECT_GT(s.keyframes, 2u);
  EXPECT_TRUE(fs::exists(s.out_dir / "CameraTrajectory.txt"));
  EXPECT_TRUE(fs::exists(s.out_dir / "KeyFrameTrajectory.txt"));
  EXPECT_TRUE(fs::exists(s.out_dir / "map.ply"));
  EXPECT_TRUE(s.metrics.contains("timings"));
  // The poses as tracking gave them, one per tracked frame, evaluated like the final trajectory.
  EXPECT_EQ(read_tum_trajectory(s.out_dir / "LiveTrajectory.txt").size(), s.tracked);
  ASSERT_TRUE(s.metrics.contains("ate_live"));
  EXPECT_LT(s.metrics.at("ate_live").at("rmse").get<double>(), 0.02);
}

TEST(EndToEnd, DeterministicModeIsByteIdentical) {
  const RunSummary a = run_on(static_4s_sequence(), test_dir("det_a"), RunMode::Deterministic, 60);
  const RunSummary b = run_on(static_4s_sequence(), test_dir("det_b"), RunMode::Deterministic, 60);
  const std::string ta = slurp(a.out_dir / "CameraTrajectory.txt");
  ASSERT_FALSE(ta.empty());
  EXPECT_EQ(ta, slurp(b.out_dir / "CameraTrajectory.txt"));
  EXPECT_EQ(slurp(a.out_dir / "map.ply"), slurp(b.out_dir / "map.ply"));
}

TEST(EndToEnd, RealTimeModeTracksTheSameSequence) {
  const RunSummary s = run_on(static_4s_sequence(), test_dir("rt_run"), RunMode::RealTime);
  EXPECT_EQ(s.tracked, s.frames);
  ASSERT_TRUE(s.ate_rmse.has_value());
  EXPECT_LT(*s.ate_rmse, 0.03);
}

// Paced real time with --drop-late reports what a robot would see: every frame either tracked (with its latency) or
// dropped because a newer one had arrived, the mapping queue, and which keyframes' Local BA was skipped or cut short.
TEST(EndToEnd, PacedRealTimeAccountsForEveryFrameAndReportsLatency) {
  const fs::path seq = static_4s_sequence();
  run::RunOptions ro;
  ro.mode = RunMode::RealTime;
  ro.pace = true;
  ro.drop_late = true;
  ro.progress = false;
  const RunSummary s = e2e::run_with(seq, test_dir("rt_paced"), ro);
  const auto& m = s.metrics;
  ASSERT_TRUE(m.contains("realtime"));
  const auto& r = m["realtime"];
  const std::size_t total = open_dataset(seq, settings_for_dataset(seq, std::nullopt))->size();
  EXPECT_EQ(s.frames + r["dropped_frames"].get<std::size_t>(), total);
  EXPECT_EQ(r["late_frames"].get<long>(), 0);  // with --drop-late a late frame is dropped, not tracked late
  EXPECT_EQ(r["latency"]["count"].get<std::size_t>(), s.frames);
  EXPECT_GT(r["latency"]["median_ms"].get<double>(), 0.0);
  EXPECT_GE(r["latency"]["p95_ms"].get<double>(), r["latency"]["median_ms"].get<double>());
  EXPECT_EQ(r["keyframes_mapped"].get<long>(), m["timings"]["keyframe_processing"]["count"].get<long>());
  EXPECT_LE(r["local_ba_skipped"].get<long>() + static_cast<long>(m["local_ba"].size()), r["keyframes_mapped"].get<long>());
  EXPECT_LE(r["local_ba_cut_short"].get<long>(), static_cast<long>(m["local_ba"].size()));
  EXPECT_GE(r["mapping_queue"]["max"].get<double>(), r["mapping_queue"]["median"].get<double>());
  // Deterministic runs have no such block: nothing there is timing-dependent.
  EXPECT_FALSE(run_on(seq, test_dir("det_no_rt"), RunMode::Deterministic, 20).metrics.contains("realtime"));
}

// A large box carried 0.6-1.5 m in front of the camera (4 s along fr3_sitting_static, seed 4): the box has more
// matches than the room behind it, and as it is carried out of the view tracking follows it unless the near-mover
// check solves the pose on the room. The test shows both sides, so it fails if the scene stops dragging.
TEST(EndToEnd, ALargeBoxCarriedOutOfTheViewDoesNotDragThePose) {
  const fs::path seq = path_sequence("large_box_seq", "rgbd_dataset_freiburg3_sitting_static", "large_box", 4.0, 4, 1.8);
  if (seq.empty()) GTEST_SKIP() << "../shared/trajectories not found";
  const RunSummary with_check = run_on(seq, test_dir("large_box_check"));
  expect_tracked_with_ate_below(with_check, 0.02);
  EXPECT_EQ(with_check.dragged_events, 0u);
  ASSERT_TRUE(with_check.ate_live_rmse.has_value());
  EXPECT_LT(*with_check.ate_live_rmse, 0.02);
  const RunSummary without = run_on(seq, test_dir("large_box_nocheck"), RunMode::Deterministic, SIZE_MAX,
                                    {"tracking.near_mover_check=false"});
  ASSERT_TRUE(without.ate_rmse.has_value());
  EXPECT_GE(without.dragged_events, 1u);
  EXPECT_GT(*without.ate_rmse, 0.04);
}

// A box of 0.9 m carried 1.1 m in front of the camera until it covers half of the view, then swept out to the right
// (fr2_desk_with_person, seed 3, 11.0-17.3 s of a 20-s sequence). The near-mover check finds it while the room
// still holds enough matches, but as it grows the room falls under the check's 30 far matches, and its own new
// points pull the pose along. Followed (tracking.near_mover_memory), its matches are left out of the solve.
TEST(EndToEnd, AMoverCoveringHalfTheViewIsFollowedAndDoesNotDragThePose) {
  const fs::path seq =
      path_sequence("large_box_fr2_s3", "rgbd_dataset_freiburg2_desk_with_person", "large_box", 20.0, 3, 61);
  if (seq.empty()) GTEST_SKIP() << "../shared/trajectories not found";
  run::RunOptions ro;
  ro.progress = false;
  ro.first = 330;
  ro.max_frames = 190;
  const RunSummary followed = e2e::run_with(seq, test_dir("large_box_followed"), ro);
  expect_tracked_with_ate_below(followed, 0.02);
  EXPECT_EQ(followed.dragged_events, 0u);
  ASSERT_TRUE(followed.ate_live_rmse.has_value());
  EXPECT_LT(*followed.ate_live_rmse, 0.025);
  const RunSummary not_followed =
      e2e::run_with(seq, test_dir("large_box_not_followed"), ro, {"tracking.near_mover_memory=0"});
  ASSERT_TRUE(not_followed.ate_live_rmse.has_value());
  EXPECT_GE(not_followed.dragged_events, 1u);
  EXPECT_GT(*not_followed.ate_live_rmse, 0.03);
}

// A real hand-held path with jitter (Bonn crowd3, 13.5-15.5 s): the camera turns by ~2 degrees between frames,
// then back, so the constant-velocity guess is off by twice that. In the generator-1 room the motion model kept
// few of its matches near the end of this window, agreeing on a pose a metre away, and without the
// reference-keyframe cross-check (tracking.motion_inlier_ratio = 0) the run ended at 47 cm instead of 0.5 cm.
// The richer generator-3 room tracks this window either way (0.4 cm); the test keeps the jerky path covered.
TEST(EndToEnd, JerkyHandHeldPathIsTracked) {
  const fs::path seq = path_sequence("jerky_seq", "rgbd_bonn_crowd3", "static", 2.0, 2, 13.5);
  if (seq.empty()) GTEST_SKIP() << "camera paths not found under " << VARSLAM_SHARED_DIR << " (../shared is absent)";
  expect_tracked_with_ate_below(run_on(seq, test_dir("jerky"), RunMode::Deterministic), 0.02);
}

// Three people walk in front of a background 4-5 m away (bonn_crowd3 path, seed 1); the boxes filter takes
// their keypoints out. What remains is far: a 20 cm sideways jump against a 2.3 deg turn moves those points by
// less than a pixel, and only depth tells the two apart. With ORB-SLAM3's depth residual (one pixel of
// virtual-stereo noise, depth.disparity_weight = 0) the pose jumped 21 cm in one frame: ATE 4.6 cm over this
// second (8.3 cm over three). Weighting the disparity as a Kinect measures it keeps the pose (1.6 cm).
TEST(EndToEnd, PeopleFilteredFromFarBackgroundKeepThePose) {
  // 3 s: the movers are planned over the whole sequence; the first second is what is run.
  const fs::path seq = path_sequence("far_background_walking_3s", "rgbd_bonn_crowd3", "walking", 3.0, 1, 12.8);
  if (seq.empty()) GTEST_SKIP() << "camera paths not found under " << VARSLAM_SHARED_DIR << " (../shared is absent)";
  Settings settings = settings_for_dataset(seq, std::nullopt);
  settings.root["semantic"]["detector"] = "boxes";
  settings.root["semantic"]["boxes_file"] = "boxes.txt";
  ASSERT_GT(slam_config_from(settings).tracking.disparity_weight, 0.0) << "the default depth residual is the disparity one";
  auto ds = open_dataset(seq, settings);
  RunOptions ro;
  ro.progress = false;
  ro.max_frames = 30;
  expect_tracked_with_ate_below(run_slam(*ds, settings, ro, test_dir("far_background")), 0.025);
}

// A 38 cm box flies past 2 m away at 0.95 m/s in front of a wall 5 m away (unknown_box, fr3_sitting_static
// path, seed 2). To the box and the wall alike this looks like the camera sliding 5 cm per frame and turning
// 0.6 deg; only the few static points nearby disagree. With the paper's tracking shape (alpha 1) tracking
// followed the box from the first frame: 47 cm over this second, 96 cm over three. The redescending default
// (alpha -2) lets the box's residuals go once they pass a few pixels: 0.3 cm.
TEST(EndToEnd, BoxFlyingPastIsNotFollowed) {
  // 3 s: the movers are planned over the whole sequence; the first second is what is run.
  const fs::path seq =
      path_sequence("box_flying_past_3s", "rgbd_dataset_freiburg3_sitting_static", "unknown_box", 3.0, 2, 10.3);
  if (seq.empty()) GTEST_SKIP() << "camera paths not found under " << VARSLAM_SHARED_DIR << " (../shared is absent)";
  expect_tracked_with_ate_below(run_on(seq, test_dir("box_flying_past"), RunMode::Deterministic, 30), 0.02);
}

// The first 3 s of fr1/desk (hand-held, turning ~25 deg/s) seen by a colour camera that reads its rows out over
// 30 ms: the top and bottom rows see the desk ~0.75 deg apart. Compensated with the motion each frame's own solve
// measures, the error falls to under half (seed 1: 4.95 -> 1.87 cm); compensated with the previous interval's
// motion alone it fell only to 3.68.
TEST(EndToEnd, RollingShutterIsCompensatedWithTheFramesOwnMotion) {
  synth::RealSensorEffects shutter;
  shutter.rolling_shutter_s = 0.03;
  const fs::path seq =
      path_sequence("desk_rolling_shutter_30ms", "rgbd_dataset_freiburg1_desk", "static", 3.0, 1, 0.0, shutter);
  if (seq.empty()) GTEST_SKIP() << "camera paths not found under " << VARSLAM_SHARED_DIR << " (../shared is absent)";
  const RunSummary off = run_on(seq, test_dir("shutter_off"), RunMode::Deterministic);
  const RunSummary on = run_on(seq, test_dir("shutter_on"), RunMode::Deterministic, SIZE_MAX,
                               {"camera.rolling_shutter_ms=30"});
  EXPECT_EQ(on.tracked, on.frames);
  ASSERT_TRUE(off.ate_rmse && on.ate_rmse);
  EXPECT_LT(*on.ate_rmse, 0.5 * *off.ate_rmse) << "compensated " << *on.ate_rmse << " m, not " << *off.ate_rmse;
}

TEST(EndToEnd, RealKitchenExcerpt) {
  const fs::path data = fs::path(VARSLAM_SHARED_DIR) / "realdata" / "7scenes_redkitchen";
  if (!fs::exists(data)) GTEST_SKIP() << "real data not found at " << data << " (../shared is absent)";
  // KinectFusion ground truth and unregistered depth: a few cm is the honest expectation on 150 frames.
  expect_tracked_with_ate_below(run_on(data, test_dir("kitchen"), RunMode::Deterministic, 150), 0.04);
}

}  // namespace
}  // namespace varslam::slam
