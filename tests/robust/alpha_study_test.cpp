// Experiment behind DESIGN.md's open question (1): which alpha the grid search picks on Gaussian noise
// (per component vs 2-D / 3-D residual norms) and with gross outliers, for several tau. Not a check:
// disabled by default, prints a markdown table. Run:
//   test_robust --gtest_also_run_disabled_tests --gtest_filter='*AlphaStudy*'
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <vector>

#include "robust/barron.hpp"

namespace varslam::robust {
namespace {

// n residual vectors of `dims` unit-Gaussian components; a fraction of the vectors is replaced by gross
// outliers whose components are uniform in [-range, range] (a mismatch or a moving object).
std::vector<double> residuals(std::size_t n, int dims, double outlier_fraction, double range, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(-range, range);
  std::vector<double> v(n * static_cast<std::size_t>(dims));
  const auto outliers = static_cast<std::size_t>(outlier_fraction * static_cast<double>(n));
  for (std::size_t i = 0; i < n; ++i)
    for (int j = 0; j < dims; ++j) v[i * static_cast<std::size_t>(dims) + static_cast<std::size_t>(j)] = i < outliers ? u(rng) : g(rng);
  return v;
}

// Mean and spread of the picked alpha over a few seeds.
void report(const char* label, int dims, AlphaFit fit, double outliers, double range, const LogPartitionTable& t) {
  constexpr int kSeeds = 5;
  double sum = 0.0, lo = 1e9, hi = -1e9;
  for (int s = 0; s < kSeeds; ++s) {
    const std::vector<double> r = residuals(10000, dims, outliers, range, 100u + static_cast<unsigned>(s));
    const double a = estimate_alpha(samples_from_residuals(r, dims, fit), t).alpha;
    sum += a;
    lo = std::min(lo, a);
    hi = std::max(hi, a);
  }
  std::printf("| %g | %s | %d | %.0f%% | +-%g | %.2f [%.1f, %.1f] |\n", t.tau(), label, dims, 100.0 * outliers, range,
              sum / kSeeds, lo, hi);
}

TEST(DISABLED_AlphaStudy, GaussianAndOutliers) {
  std::printf("| tau | fit | dims | outliers | outlier range | alpha mean [min, max] over 5 seeds, 10k residuals |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (const double tau : {3.0, 5.0, 10.0, 20.0}) {
    const LogPartitionTable t(tau);
    for (const double out : {0.0, 0.1, 0.3, 0.5}) {
      report("component", 2, AlphaFit::PerComponent, out, 20.0, t);
      report("norm", 2, AlphaFit::ResidualNorm, out, 20.0, t);
      report("norm", 3, AlphaFit::ResidualNorm, out, 20.0, t);
    }
  }
}

// How much the pick depends on how far the outliers are (beyond tau they all count as tau).
TEST(DISABLED_AlphaStudy, OutlierRange) {
  std::printf("| tau | fit | dims | outliers | outlier range | alpha mean [min, max] over 5 seeds, 10k residuals |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (const double tau : {5.0, 10.0, 20.0}) {
    const LogPartitionTable t(tau);
    for (const double range : {5.0, 10.0, 50.0, 500.0})
      for (const double out : {0.1, 0.3}) report("component", 2, AlphaFit::PerComponent, out, range, t);
  }
}

}  // namespace
}  // namespace varslam::robust
