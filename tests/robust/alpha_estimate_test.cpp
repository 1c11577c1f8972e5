// Alpha estimation: fast sweep against brute force, behaviour on Gaussian noise and outliers,
// the sample builders, determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <stdexcept>
#include <vector>

#include "robust/barron.hpp"

namespace varslam::robust {
namespace {

// Exact NLL of DESIGN.md at grid index k: N log Z + sum rho(min(|x|/c, tau)).
double brute_nll(const std::vector<double>& xs, const LogPartitionTable& t, std::size_t k, double c) {
  double sum = 0.0;
  for (double x : xs) sum += barron_rho(std::min(std::abs(x) / c, t.tau()), t.alphas()[k], 1.0);
  return static_cast<double>(xs.size()) * t.log_z()[k] + sum;
}

std::vector<double> gaussian(std::size_t n, double sigma, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<double> v(n);
  for (double& x : v) x = g(rng);
  return v;
}

// Replaces a fraction of the samples by gross outliers uniform in [-range, range].
void add_outliers(std::vector<double>& v, double fraction, double range, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-range, range);
  const auto count = static_cast<std::size_t>(fraction * static_cast<double>(v.size()));
  for (std::size_t i = 0; i < count; ++i) v[i] = u(rng);
}

double fit(const std::vector<double>& components, int dims, AlphaFit how, const LogPartitionTable& t) {
  const std::vector<double> s = samples_from_residuals(components, dims, how);
  return estimate_alpha(s, t).alpha;
}

class AlphaEstimateTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { table_ = new LogPartitionTable(kTau); }
  static void TearDownTestSuite() { delete table_; }
  static constexpr double kTau = 10.0;
  static const LogPartitionTable* table_;
};
const LogPartitionTable* AlphaEstimateTest::table_ = nullptr;

TEST_F(AlphaEstimateTest, FastSweepPicksTheBruteForceMinimum) {
  // Gaussian, Gaussian + outliers, Laplacian, Student-t(1.5), scaled data with c != 1.
  std::vector<std::vector<double>> sets;
  sets.push_back(gaussian(3000, 1.0, 1));
  sets.push_back(gaussian(3000, 1.0, 2));
  add_outliers(sets.back(), 0.3, 30.0, 3);
  {
    std::mt19937_64 rng(4);
    std::exponential_distribution<double> e(1.0);
    std::bernoulli_distribution sign(0.5);
    std::vector<double> v(3000);
    for (double& x : v) x = sign(rng) ? e(rng) : -e(rng);
    sets.push_back(v);
  }
  {
    std::mt19937_64 rng(5);
    std::student_t_distribution<double> st(1.5);
    std::vector<double> v(3000);
    for (double& x : v) x = st(rng);
    sets.push_back(v);
  }
  for (const double c : {1.0, 2.5}) {
    for (const std::vector<double>& xs : sets) {
      std::vector<double> scaled = xs;
      for (double& x : scaled) x *= c;
      const AlphaEstimate est = estimate_alpha(scaled, *table_, c);
      std::size_t best = 0;
      double best_nll = std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < table_->alphas().size(); ++k) {
        const double nll = brute_nll(scaled, *table_, k, c);
        if (nll < best_nll) {
          best_nll = nll;
          best = k;
        }
      }
      EXPECT_EQ(est.alpha, table_->alphas()[best]);
      EXPECT_NEAR(est.nll, best_nll, 1e-9 * std::abs(est.nll));
    }
  }
}

TEST(AlphaNllCurve, BinnedSweepIsWithinTenthOfMicroPerSampleOfExact) {
  // The binned sweep against the exact NLL at every grid alpha, for each tau of DESIGN.md's table,
  // on clean and on heavily contaminated data (outliers far beyond tau exercise the clamp).
  double worst = 0.0;
  for (const double tau : {3.0, 5.0, 10.0, 20.0}) {
    const LogPartitionTable table(tau);
    std::vector<double> clean = gaussian(2000, 1.0, 51);
    std::vector<double> dirty = gaussian(2000, 1.0, 52);
    add_outliers(dirty, 0.5, 3.0 * tau, 53);
    for (const std::vector<double>* xs : {&clean, &dirty}) {
      const std::vector<double> curve = alpha_nll_curve(*xs, table);
      ASSERT_EQ(curve.size(), table.alphas().size());
      for (std::size_t k = 0; k < curve.size(); ++k) {
        const double per_sample = std::abs(curve[k] - brute_nll(*xs, table, k, 1.0)) / 2000.0;
        worst = std::max(worst, per_sample);
      }
    }
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", worst);
  RecordProperty("worst_nll_error_per_sample", text);
  EXPECT_LT(worst, 1e-7);  // measured 8.5e-8 with bins of width 0.03 in log(1 + z)
}

TEST_F(AlphaEstimateTest, GaussianPerComponentIsAtTheTopOfTheGrid) {
  const std::vector<double> e = gaussian(10000, 1.0, 11);
  EXPECT_GE(fit(e, 2, AlphaFit::PerComponent, *table_), 1.8);
}

TEST_F(AlphaEstimateTest, ResidualNormsBiasAlphaLow) {
  // Same Gaussian noise, fitted the paper's way: the norm of a 2-D / 3-D Gaussian is not Barron-shaped.
  const std::vector<double> e2 = gaussian(20000, 1.0, 12);  // 10k 2-D residuals
  const std::vector<double> e3 = gaussian(30000, 1.0, 13);  // 10k 3-D residuals
  const double a2 = fit(e2, 2, AlphaFit::ResidualNorm, *table_);
  const double a3 = fit(e3, 3, AlphaFit::ResidualNorm, *table_);
  EXPECT_LT(a2, 1.8);
  EXPECT_LT(a3, a2);
  EXPECT_GE(fit(e2, 2, AlphaFit::PerComponent, *table_), 1.8);
  EXPECT_GE(fit(e3, 3, AlphaFit::PerComponent, *table_), 1.8);
}

TEST_F(AlphaEstimateTest, GrossOutliersDriveAlphaDown) {
  std::vector<double> e = gaussian(10000, 1.0, 21);
  const double clean = fit(e, 2, AlphaFit::PerComponent, *table_);
  add_outliers(e, 0.3, kTau, 22);
  const double dirty = fit(e, 2, AlphaFit::PerComponent, *table_);
  EXPECT_LT(dirty, 0.0);
  EXPECT_LT(dirty, clean - 2.0);
}

TEST_F(AlphaEstimateTest, ScaleAndSignInvariant) {
  std::vector<double> e = gaussian(5000, 1.0, 31);
  add_outliers(e, 0.1, 20.0, 32);
  const AlphaEstimate ref = estimate_alpha(e, *table_, 1.0);
  std::vector<double> scaled = e;
  for (double& x : scaled) x *= -4.0;
  const AlphaEstimate s = estimate_alpha(scaled, *table_, 4.0);
  EXPECT_EQ(s.alpha, ref.alpha);
  EXPECT_NEAR(s.nll, ref.nll, 1e-9 * std::abs(ref.nll));
}

TEST_F(AlphaEstimateTest, DeterministicAndOrderIndependent) {
  std::vector<double> e = gaussian(10000, 1.0, 41);
  add_outliers(e, 0.2, 15.0, 42);
  const AlphaEstimate a = estimate_alpha(e, *table_);
  const AlphaEstimate b = estimate_alpha(e, *table_);
  EXPECT_EQ(a.alpha, b.alpha);
  EXPECT_EQ(a.nll, b.nll);
  std::vector<double> shuffled = e;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(43));
  const AlphaEstimate c = estimate_alpha(shuffled, *table_);
  EXPECT_EQ(c.alpha, a.alpha);
  EXPECT_NEAR(c.nll, a.nll, 1e-9 * std::abs(a.nll));
}

TEST_F(AlphaEstimateTest, EdgeCases) {
  const AlphaEstimate none = estimate_alpha(std::vector<double>{}, *table_);
  EXPECT_EQ(none.alpha, 2.0);
  EXPECT_EQ(none.nll, 0.0);
  // All-zero residuals: only log Z matters, the Gaussian has the smallest.
  EXPECT_EQ(estimate_alpha(std::vector<double>(100, 0.0), *table_).alpha, 2.0);
  EXPECT_THROW(estimate_alpha(std::vector<double>{1.0}, *table_, 0.0), std::invalid_argument);
  EXPECT_THROW(estimate_alpha(std::vector<double>{std::nan("")}, *table_), std::invalid_argument);
  // Samples beyond tau count as tau.
  const std::vector<double> far = {1.0, -2.0, 1e6, 0.5};
  const std::vector<double> clamped = {1.0, -2.0, kTau, 0.5};
  EXPECT_EQ(estimate_alpha(far, *table_).nll, estimate_alpha(clamped, *table_).nll);
}

TEST(SamplesFromResiduals, ComponentsAndNorms) {
  const std::vector<double> r = {3.0, 4.0, -1.0, 0.0, 0.0, -2.0};
  EXPECT_EQ(samples_from_residuals(r, 2, AlphaFit::PerComponent), r);
  EXPECT_EQ(samples_from_residuals(r, 3, AlphaFit::PerComponent), r);
  EXPECT_EQ(samples_from_residuals(r, 2, AlphaFit::ResidualNorm), (std::vector<double>{5.0, 1.0, 2.0}));
  const std::vector<double> n3 = samples_from_residuals(r, 3, AlphaFit::ResidualNorm);
  ASSERT_EQ(n3.size(), 2u);
  EXPECT_DOUBLE_EQ(n3[0], std::sqrt(26.0));
  EXPECT_DOUBLE_EQ(n3[1], 2.0);
  EXPECT_TRUE(samples_from_residuals({}, 3, AlphaFit::ResidualNorm).empty());
  EXPECT_THROW(samples_from_residuals(r, 4, AlphaFit::ResidualNorm), std::invalid_argument);
  EXPECT_THROW(samples_from_residuals(r, 0, AlphaFit::PerComponent), std::invalid_argument);
}

}  // namespace
}  // namespace varslam::robust
