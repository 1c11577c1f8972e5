// The whole pipeline on short sequences: synthetic (always) and the real 7-Scenes excerpt (when ../shared
// is present). Bounds are loose enough for noise, tight enough that a broken tracker fails them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <unistd.h>

#include "e2e_support.hpp"

namespace varslam::slam {
namespace {

namespace fs = std::filesystem;
using e2e::cached_sequence;
using e2e::run_on;

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

fs::path test_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("varslam_e2e_" + name);
  fs::remove_all(d);
  return d;
}

const fs::path& static_sequence() {
  static const fs::path dir = [] {
    synth::SynthConfig cfg;
    cfg.scenario = "static";
    cfg.seconds = 4.0;
    cfg.seed = 7;
    return cached_sequence("static_seq", cfg);
  }();
  return dir;
}

TEST(EndToEnd, StaticSyntheticSceneIsTrackedAccurately) {
  const RunSummary s = run_on(static_sequence(), test_dir("static_run"), RunMode::Deterministic);
  EXPECT_EQ(s.lost, 0u);
  EXPECT_EQ(s.tracked, s.frames);
  ASSERT_TRUE(s.ate_rmse.has_value());
  EXPECT_LT(*s.ate_rmse, 0.02) << "ATE RMSE " << *s.ate_rmse << " m";
  EXPECT_GT(s.keyframes, 2u);
  EXPECT_TRUE(fs::exists(s.out_dir / "CameraTrajectory.txt"));
  EXPECT_TRUE(fs::exists(s.out_dir / "KeyFrameTrajectory.txt"));
  EXPECT_TRUE(fs::exists(s.out_dir / "map.ply"));
  EXPECT_TRUE(s.metrics.contains("timings"));
}

TEST(EndToEnd, DeterministicModeIsByteIdentical) {
  const RunSummary a = run_on(static_sequence(), test_dir("det_a"), RunMode::Deterministic, 60);
  const RunSummary b = run_on(static_sequence(), test_dir("det_b"), RunMode::Deterministic, 60);
  const std::string ta = slurp(a.out_dir / "CameraTrajectory.txt");
  ASSERT_FALSE(ta.empty());
  EXPECT_EQ(ta, slurp(b.out_dir / "CameraTrajectory.txt"));
  EXPECT_EQ(slurp(a.out_dir / "map.ply"), slurp(b.out_dir / "map.ply"));
}

TEST(EndToEnd, RealTimeModeTracksTheSameSequence) {
  const RunSummary s = run_on(static_sequence(), test_dir("rt_run"), RunMode::RealTime);
  EXPECT_EQ(s.tracked, s.frames);
  ASSERT_TRUE(s.ate_rmse.has_value());
  EXPECT_LT(*s.ate_rmse, 0.03);
}

// A real hand-held path with jitter (Bonn crowd3, 13.5-15.5 s): the camera turns by ~2 degrees between frames,
// then back, so the constant-velocity guess is off by twice that. In the generator-1 room the motion model kept
// few of its matches near the end of this window, agreeing on a pose a metre away, and without the
// reference-keyframe cross-check (tracking.motion_inlier_ratio = 0) the run ended at 47 cm instead of 0.5 cm.
// The richer generator-3 room tracks this window either way (0.4 cm); the test keeps the jerky path covered.
TEST(EndToEnd, JerkyHandHeldPathIsTracked) {
  const fs::path path = fs::path(VARSLAM_SHARED_DIR) / "trajectories" / "rgbd_bonn_crowd3";
  if (!fs::exists(path)) GTEST_SKIP() << "camera paths not found at " << path << " (../shared is absent)";
  synth::SynthConfig cfg;
  cfg.scenario = "static";
  cfg.seconds = 2.0;
  cfg.seed = 2;
  cfg.path_file = path;
  cfg.path_start = 13.5;
  const fs::path seq = cached_sequence("jerky_seq", cfg);
  const RunSummary s = run_on(seq, test_dir("jerky"), RunMode::Deterministic);
  EXPECT_EQ(s.tracked, s.frames);
  ASSERT_TRUE(s.ate_rmse.has_value());
  EXPECT_LT(*s.ate_rmse, 0.02) << "ATE RMSE " << *s.ate_rmse << " m";
}

// Three people walk in front of a background 4-5 m away (bonn_crowd3 path, seed 1); the boxes filter takes
// their keypoints out. What remains is far: a 20 cm sideways jump against a 2.3 deg turn moves those points by
// less than a pixel, and only depth tells the two apart. With ORB-SLAM3's depth residual (one pixel of
// virtual-stereo noise, depth.disparity_weight = 0) the pose jumped 21 cm in one frame: ATE 4.6 cm over this
// second (8.3 cm over three). Weighting the disparity as a Kinect measures it keeps the pose (1.6 cm).
TEST(EndToEnd, PeopleFilteredFromFarBackgroundKeepThePose) {
  const fs::path path = fs::path(VARSLAM_SHARED_DIR) / "trajectories" / "rgbd_bonn_crowd3";
  if (!fs::exists(path)) GTEST_SKIP() << "camera paths not found at " << path << " (../shared is absent)";
  synth::SynthConfig cfg;
  cfg.scenario = "walking";
  cfg.seconds = 3.0;  // the movers are planned over the whole sequence; the first second is what is run
  cfg.seed = 1;
  cfg.path_file = path;
  cfg.path_start = 12.8;
  const fs::path seq = cached_sequence("far_background_walking_3s", cfg);
  Settings settings = settings_for_dataset(seq, std::nullopt);
  settings.root["semantic"]["detector"] = "boxes";
  settings.root["semantic"]["boxes_file"] = "boxes.txt";
  const SlamConfig slam = slam_config_from(settings);
  ASSERT_GT(slam.tracking.disparity_weight, 0.0) << "the default depth residual is the disparity one";
  auto ds = open_dataset(seq, settings);
  RunOptions ro;
  ro.progress = false;
  ro.max_frames = 30;
  const RunSummary s = run_slam(*ds, settings, slam, ro, test_dir("far_background"));
  EXPECT_EQ(s.tracked, s.frames);
  ASSERT_TRUE(s.ate_rmse.has_value());
  EXPECT_LT(*s.ate_rmse, 0.025) << "ATE RMSE " << *s.ate_rmse << " m";
}

// A 38 cm box flies past 2 m away at 0.95 m/s in front of a wall 5 m away (unknown_box, fr3_sitting_static
// path, seed 2). To the box and the wall alike this looks like the camera sliding 5 cm per frame and turning
// 0.6 deg; only the few static points nearby disagree. With the paper's tracking shape (alpha 1) tracking
// followed the box from the first frame: 47 cm over this second, 96 cm over three. The redescending default
// (alpha -2) lets the box's residuals go once they pass a few pixels: 0.3 cm.
TEST(EndToEnd, BoxFlyingPastIsNotFollowed) {
  const fs::path path = fs::path(VARSLAM_SHARED_DIR) / "trajectories" / "rgbd_dataset_freiburg3_sitting_static";
  if (!fs::exists(path)) GTEST_SKIP() << "camera paths not found at " << path << " (../shared is absent)";
  synth::SynthConfig cfg;
  cfg.scenario = "unknown_box";
  cfg.seconds = 3.0;  // the movers are planned over the whole sequence; the first second is what is run
  cfg.seed = 2;
  cfg.path_file = path;
  cfg.path_start = 10.3;
  const fs::path seq = cached_sequence("box_flying_past_3s", cfg);
  const RunSummary s = run_on(seq, test_dir("box_flying_past"), RunMode::Deterministic, 30);
  EXPECT_EQ(s.tracked, s.frames);
  ASSERT_TRUE(s.ate_rmse.has_value());
  EXPECT_LT(*s.ate_rmse, 0.02) << "ATE RMSE " << *s.ate_rmse << " m";
}

TEST(EndToEnd, RealKitchenExcerpt) {
  const fs::path data = fs::path(VARSLAM_SHARED_DIR) / "realdata" / "7scenes_redkitchen";
  if (!fs::exists(data)) GTEST_SKIP() << "real data not found at " << data << " (../shared is absent)";
  const RunSummary s = run_on(data, test_dir("kitchen"), RunMode::Deterministic, 150);
  EXPECT_EQ(s.tracked, s.frames);
  ASSERT_TRUE(s.ate_rmse.has_value());
  // KinectFusion ground truth and unregistered depth: a few cm is the honest expectation on 150 frames.
  EXPECT_LT(*s.ate_rmse, 0.04) << "ATE RMSE " << *s.ate_rmse << " m";
}

}  // namespace
}  // namespace varslam::slam
