// Speed of the adaptive robust kernel: alpha estimation on a Local-BA-sized sample set, the kernel
// itself, and the one-off partition table. Run: build/bin/robust_bench --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "robust/barron.hpp"

namespace {

using varslam::robust::LogPartitionTable;

std::vector<double> samples(std::size_t n, double outlier_fraction, double tau) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(-tau, tau);
  std::bernoulli_distribution is_outlier(outlier_fraction);
  std::vector<double> v(n);
  for (double& x : v) x = is_outlier(rng) ? u(rng) : g(rng);
  return v;
}

const LogPartitionTable& table(double tau) {
  static const LogPartitionTable t5(5.0), t10(10.0), t20(20.0);
  return tau == 5.0 ? t5 : tau == 10.0 ? t10 : t20;
}

// args: number of samples, outlier percent, tau
void BM_EstimateAlpha(benchmark::State& state) {
  const double tau = static_cast<double>(state.range(2));
  const std::vector<double> v =
      samples(static_cast<std::size_t>(state.range(0)), static_cast<double>(state.range(1)) / 100.0, tau);
  const LogPartitionTable& t = table(tau);
  for (auto _ : state) benchmark::DoNotOptimize(varslam::robust::estimate_alpha(v, t));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_EstimateAlpha)
    ->Args({10000, 0, 5})
    ->Args({10000, 30, 5})
    ->Args({10000, 0, 10})
    ->Args({10000, 30, 10})
    ->Args({10000, 30, 20})
    ->Args({1000, 30, 10})
    ->Unit(benchmark::kMicrosecond);

// Brute force reference: the exact NLL at all 121 alphas (what the binned sweep replaces).
void BM_EstimateAlphaBruteForce(benchmark::State& state) {
  const std::vector<double> v = samples(10000, 0.3, 10.0);
  const LogPartitionTable& t = table(10.0);
  for (auto _ : state) {
    double best = 1e300;
    for (std::size_t k = 0; k < t.alphas().size(); ++k) {
      double sum = static_cast<double>(v.size()) * t.log_z()[k];
      for (double x : v) sum += varslam::robust::barron_rho(std::min(std::abs(x), 10.0), t.alphas()[k], 1.0);
      best = std::min(best, sum);
    }
    benchmark::DoNotOptimize(best);
  }
}
BENCHMARK(BM_EstimateAlphaBruteForce)->Unit(benchmark::kMillisecond);

void BM_BarronKernel(benchmark::State& state) {
  const double alpha = static_cast<double>(state.range(0)) / 10.0;
  const std::vector<double> v = samples(4096, 0.3, 10.0);
  double out[3];
  for (auto _ : state) {
    double acc = 0.0;
    for (double x : v) {
      varslam::robust::barron_kernel(x * x, alpha, 1.0, out);
      acc += out[0] + out[1] + out[2];
    }
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(v.size()));
}
BENCHMARK(BM_BarronKernel)->Arg(20)->Arg(10)->Arg(0)->Arg(-35)->Unit(benchmark::kMicrosecond);

void BM_LogPartitionTable(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(LogPartitionTable(10.0));
}
BENCHMARK(BM_LogPartitionTable)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
