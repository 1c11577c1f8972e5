// Optimiser timings. Compare medians: pose-only Huber vs Barron alpha = 1 (target ratio <= 1.07) for each
// solver (Dedicated vs Ceres decides PoseOptimConfig's default), Local BA Huber vs BarronAdaptive (target
// ratio <= 1.5) on a realistic window (10 keyframes, 2000 points, ~8000 observations).
//   build/bin/optim_bench --benchmark_repetitions=15 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "optim/local_ba.hpp"
#include "optim/pose_optimizer.hpp"
#include "optim/synthetic_problems.hpp"

namespace {

using namespace varslam;
using namespace varslam::optim;

// args: kernel (0 Huber, 1 Barron alpha = 1), solver (0 Dedicated, 1 Ceres)
void BM_PoseOptimization(benchmark::State& state) {
  const PinholeCamera cam;
  SyntheticPoseOptions opt;
  opt.observations = 500;
  opt.outlier_fraction = 0.15;
  const SyntheticPose s = make_synthetic_pose(cam, opt);
  PoseOptimConfig cfg;
  cfg.kernel.type = state.range(0) == 0 ? KernelType::Huber : KernelType::BarronFixed;
  cfg.kernel.barron_alpha = 1.0;
  cfg.solver = state.range(1) == 0 ? PoseSolver::Dedicated : PoseSolver::Ceres;
  int inliers = 0;
  for (auto _ : state) {
    Eigen::Isometry3d T = s.T_init;
    inliers = optimize_pose(cam, T, s.points_w, s.obs, cfg).inliers;
    benchmark::DoNotOptimize(T);
  }
  state.counters["inliers"] = inliers;
  state.SetLabel(std::string(state.range(0) == 0 ? "Huber" : "Barron1") + "/" +
                 (state.range(1) == 0 ? "Dedicated" : "Ceres"));
}
BENCHMARK(BM_PoseOptimization)
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->ArgNames({"kernel", "solver"});

// One kernel evaluation on a spread of squared errors: the per-observation cost behind the ratios above.
// args: kernel (0 Huber, 1 Barron alpha = 1)
void BM_KernelEvaluation(benchmark::State& state) {
  KernelConfig k;
  k.type = state.range(0) == 0 ? KernelType::Huber : KernelType::BarronFixed;
  const Kernel kernel(k, 1.0);  // as the solvers hold it: built once per solve
  std::vector<double> s(1024);
  for (std::size_t i = 0; i < s.size(); ++i) s[i] = 0.01 * static_cast<double>(i);
  double out[3] = {0.0, 0.0, 0.0}, sum = 0;
  for (auto _ : state) {
    for (double x : s) {
      kernel.evaluate(3, x, out);
      sum += out[1];
    }
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.size()));
  state.SetLabel(state.range(0) == 0 ? "Huber" : "Barron1");
}
BENCHMARK(BM_KernelEvaluation)->Arg(0)->Arg(1)->ArgName("kernel");

// One alpha fit on the residual norms of a Local BA window (~9000 samples): paid once per outer iteration.
void BM_AlphaFit(benchmark::State& state) {
  std::mt19937 rng(1);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<double> samples(9000);
  for (double& x : samples) x = std::abs(n01(rng)) * (rng() % 5 == 0 ? 10.0 : 1.0);
  KernelConfig k;
  k.type = KernelType::BarronAdaptive;
  fit_alpha(k, samples, 1.0);  // builds the log-partition table outside the timing
  for (auto _ : state) benchmark::DoNotOptimize(fit_alpha(k, samples, 1.0).applied);
}
BENCHMARK(BM_AlphaFit)->Unit(benchmark::kMillisecond);

// args: kernel (0 Huber, 1 BarronAdaptive), initial error in percent of the default perturbation (100 = 5 cm /
// 0.01 rad on every free keyframe and 5 cm on every point; 20 = a warm window as local mapping usually sees it)
void BM_LocalBa(benchmark::State& state) {
  const PinholeCamera cam;
  SyntheticBaOptions opt;
  opt.keyframes = 10;
  opt.fixed_keyframes = 2;
  opt.points = 2000;
  opt.observe_probability = 0.45;
  opt.pixel_noise = 0.5;
  const double scale = 0.01 * static_cast<double>(state.range(1));
  opt.translation_error *= scale;
  opt.rotation_error *= scale;
  opt.point_error *= scale;
  const SyntheticBa s = make_synthetic_ba(cam, opt);
  BaConfig cfg;
  cfg.kernel.type = state.range(0) == 0 ? KernelType::Huber : KernelType::BarronAdaptive;
  int iterations = 0;
  for (auto _ : state) {
    BaProblem p = s.initial;
    iterations = solve_local_ba(cam, p, cfg).solver_iterations;
    benchmark::DoNotOptimize(p);
  }
  state.counters["observations"] = static_cast<double>(s.initial.observations.size());
  state.counters["solver_iterations"] = iterations;
  state.SetLabel(state.range(0) == 0 ? "Huber" : "BarronAdaptive");
}
BENCHMARK(BM_LocalBa)
    ->ArgsProduct({{0, 1}, {100, 20}})
    ->Unit(benchmark::kMillisecond)
    ->ArgNames({"kernel", "perturbation"});

}  // namespace

BENCHMARK_MAIN();
