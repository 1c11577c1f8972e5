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
