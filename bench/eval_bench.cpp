// Evaluation cost on the largest shared sequence (fr2_desk_with_person: 36k ground-truth poses, 4k estimate
// poses), and SVG rendering of its top view.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "eval/ate.hpp"
#include "eval/eval_report.hpp"
#include "eval/rpe.hpp"
#include "io/trajectory_io.hpp"

namespace {

struct Data {
  varslam::Trajectory gt, est;
  bool ok = false;
};

const Data& data() {
  static const Data d = [] {
    Data x;
    const auto dir = std::filesystem::path(VARSLAM_SHARED_DIR) / "trajectories" / "rgbd_dataset_freiburg2_desk_with_person";
    if (!std::filesystem::exists(dir / "groundtruth.txt")) return x;
    x.gt = varslam::read_tum_trajectory(dir / "groundtruth.txt");
    x.est = varslam::read_tum_trajectory(dir / "reference_estimate_CameraTrajectory.txt");
    x.ok = true;
    return x;
  }();
  return d;
}

void BM_Associate(benchmark::State& state) {
  if (!data().ok) return state.SkipWithError("shared data missing");
  for (auto _ : state) benchmark::DoNotOptimize(varslam::associate_timestamps(data().gt, data().est));
}
BENCHMARK(BM_Associate)->Unit(benchmark::kMillisecond);

void BM_Ate(benchmark::State& state) {
  if (!data().ok) return state.SkipWithError("shared data missing");
  for (auto _ : state) benchmark::DoNotOptimize(varslam::evaluate_ate(data().gt, data().est));
}
BENCHMARK(BM_Ate)->Unit(benchmark::kMillisecond);

void BM_Rpe(benchmark::State& state) {
  if (!data().ok) return state.SkipWithError("shared data missing");
  for (auto _ : state) benchmark::DoNotOptimize(varslam::evaluate_rpe(data().gt, data().est));
}
BENCHMARK(BM_Rpe)->Unit(benchmark::kMillisecond);

void BM_TopViewSvg(benchmark::State& state) {
  if (!data().ok) return state.SkipWithError("shared data missing");
  const auto ate = varslam::evaluate_ate(data().gt, data().est);
  for (auto _ : state) benchmark::DoNotOptimize(varslam::render_svg(varslam::trajectory_top_view_plot(data().gt, ate)));
}
BENCHMARK(BM_TopViewSvg)->Unit(benchmark::kMillisecond);

}  // namespace
BENCHMARK_MAIN();
