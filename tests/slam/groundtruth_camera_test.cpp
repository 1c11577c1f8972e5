// Which camera the ground truth is of (eval.groundtruth_camera): 7-Scenes' poses are its depth camera's, a few
// centimetres beside the colour camera we track. With `depth` the run's own trajectory is unchanged and only the
// evaluation moves it by the registration's baseline.
#include <gtest/gtest.h>

#include <filesystem>

#include "e2e_support.hpp"
#include "eval/ate.hpp"
#include "io/trajectory_io.hpp"
#include "file_text.hpp"

namespace varslam::slam {
namespace {

namespace fs = std::filesystem;

using test::slurp;

TEST(GroundTruthCamera, TheKitchenIsEvaluatedAtItsDepthCameraWhenAsked) {
  const fs::path kitchen = fs::path(VARSLAM_SHARED_DIR) / "realdata" / "7scenes_redkitchen";
  if (!fs::exists(kitchen / "rgb.txt")) GTEST_SKIP() << "no " << kitchen;
  const fs::path out = fs::temp_directory_path() / ("varslam_gt_camera_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const run::RunSummary colour = e2e::run_on(kitchen, out / "colour", RunMode::Deterministic, 90,
                                             {"semantic.detector=none"});
  const run::RunSummary depth = e2e::run_on(kitchen, out / "depth", RunMode::Deterministic, 90,
                                            {"semantic.detector=none", "eval.groundtruth_camera=depth"});
  EXPECT_EQ(colour.metrics["ate_camera"], "colour");
  EXPECT_EQ(depth.metrics["ate_camera"], "depth");
  const double baseline = depth.metrics["depth_registration"]["baseline_x_m"].get<double>();
  EXPECT_LT(baseline, -0.01);  // Kinect v1: the infrared camera sits beside the colour camera
  // The same estimate, evaluated at another camera: the depth camera's positions are the colour camera's moved by
  // the baseline along its own x axis.
  const std::string estimate = slurp(out / "colour" / "CameraTrajectory.txt");
  ASSERT_FALSE(estimate.empty());
  EXPECT_EQ(slurp(out / "depth" / "CameraTrajectory.txt"), estimate);
  Trajectory moved = read_tum_trajectory(out / "colour" / "CameraTrajectory.txt");
  for (StampedPose& p : moved) p.T_wc.translation() += p.T_wc.linear() * Eigen::Vector3d(baseline, 0, 0);
  const AteResult expected = evaluate_ate(read_tum_trajectory(kitchen / "groundtruth.txt"), moved);
  EXPECT_NEAR(depth.metrics["ate"]["rmse"].get<double>(), expected.stats.rmse, 1e-9);
  EXPECT_GT(std::abs(depth.metrics["ate"]["rmse"].get<double>() - colour.metrics["ate"]["rmse"].get<double>()), 1e-4);
  fs::remove_all(out);
}

// Registered depth (the synthetic sequences, TUM, Bonn) has one camera: nothing to move, and the metrics say so.
TEST(GroundTruthCamera, RegisteredDepthHasOneCamera) {
  const fs::path seq = e2e::static_4s_sequence();
  const fs::path out = fs::temp_directory_path() / ("varslam_gt_camera_reg_" + std::to_string(::getpid()));
  const run::RunSummary s =
      e2e::run_on(seq, out, RunMode::Deterministic, 30, {"eval.groundtruth_camera=depth"});
  EXPECT_EQ(s.metrics["ate_camera"], "colour");
  fs::remove_all(out);
}

}  // namespace
}  // namespace varslam::slam
