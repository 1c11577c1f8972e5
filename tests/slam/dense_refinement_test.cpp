// The dense refinement at the end of a run (loop.final_dense_refine) on the real kitchen: keyframes 5 s apart that
// see the same surfaces through different map points are tied by their depth, and the drift between them shrinks.
#include <gtest/gtest.h>

#include <filesystem>

#include "e2e_support.hpp"

namespace varslam::slam {
namespace {

namespace fs = std::filesystem;

TEST(DenseRefinement, DistantKeyframesOfTheKitchenAgreeBetterAndTheTrajectoryFollowsThem) {
  const fs::path kitchen = fs::path(VARSLAM_SHARED_DIR) / "realdata" / "7scenes_redkitchen";
  if (!fs::exists(kitchen / "rgb.txt")) GTEST_SKIP() << "no " << kitchen;
  const fs::path out = fs::temp_directory_path() / ("varslam_dense_refine_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const std::vector<std::string> base = {"semantic.detector=none", "eval.groundtruth_camera=depth"};
  std::vector<std::string> refined = base;
  refined.push_back("loop.final_dense_refine=true");
  // 10 s: two pairs of keyframes 5 s apart overlap (measured: 3.79 -> 3.61 cm, long range 0.99 -> 0.63 %).
  const run::RunSummary off = e2e::run_on(kitchen, out / "off", RunMode::Deterministic, 300, base);
  const run::RunSummary on = e2e::run_on(kitchen, out / "on", RunMode::Deterministic, 300, refined);
  const auto long_range = [](const run::RunSummary& s) {
    return s.metrics["sensor"]["long_range_consistency"]["mean"].get<double>();
  };
  EXPECT_LT(long_range(on), 0.8 * long_range(off));
  EXPECT_LT(on.metrics["ate"]["rmse"].get<double>(), off.metrics["ate"]["rmse"].get<double>() - 0.001);
  EXPECT_EQ(on.tracked, off.tracked);
  fs::remove_all(out);
}

}  // namespace
}  // namespace varslam::slam
