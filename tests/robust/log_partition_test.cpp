// Truncated log-partition: DESIGN.md reference table, closed forms, the tabulated grid.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "robust/barron.hpp"

namespace varslam::robust {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Reference {
  double alpha, tau, log_z;
};

// DESIGN.md section 2 (5 decimals, 6 for tau = inf).
const Reference kDesignTable[] = {
    {2, 3, 0.91624},   {2, 5, 0.91894},   {2, 10, 0.91894},  {2, 20, 0.91894},  {2, kInf, 0.918939},
    {1, 3, 1.10996},   {1, 5, 1.17515},   {1, 10, 1.18542},  {1, 20, 1.18550},  {1, kInf, 1.185495},
    {0, 3, 1.16219},   {0, 5, 1.29835},   {0, 10, 1.39761},  {0, 20, 1.44532},  {0, kInf, 1.491303},
    {-1, 3, 1.18894},  {-1, 5, 1.37567},  {-1, 10, 1.60291}, {-1, 20, 1.85543},
    {-2, 3, 1.20522},  {-2, 5, 1.42580},  {-2, 10, 1.74579}, {-2, 20, 2.14539},
    {-10, 3, 1.24583}, {-10, 5, 1.54971}, {-10, 10, 2.04434}, {-10, 20, 2.62089},
};

TEST(LogPartition, MatchesDesignTable) {
  for (const Reference& r : kDesignTable) {
    const double tol = std::isinf(r.tau) ? 1e-6 : 1e-5;  // half a unit in the last printed digit
    EXPECT_NEAR(log_partition(r.alpha, r.tau), r.log_z, tol) << "alpha=" << r.alpha << " tau=" << r.tau;
  }
}

TEST(LogPartition, ClosedFormsToHighAccuracy) {
  for (double tau : {0.5, 1.0, 3.0, 5.0, 10.0, 20.0, 1e3}) {
    // Gaussian: Z = sqrt(2 pi) erf(tau / sqrt 2).
    EXPECT_NEAR(log_partition(2.0, tau), std::log(std::sqrt(2.0 * std::numbers::pi) * std::erf(tau / std::sqrt(2.0))),
                1e-10)
        << tau;
    // Cauchy: Z = 2 sqrt 2 atan(tau / sqrt 2).
    EXPECT_NEAR(log_partition(0.0, tau), std::log(2.0 * std::sqrt(2.0) * std::atan(tau / std::sqrt(2.0))), 1e-10)
        << tau;
    // Welsch: the density is exp(-1) exp(exp(-x^2/2)), bounded: Z > 2 tau / e.
    EXPECT_GT(log_partition(-kInf, tau), std::log(2.0 * tau / std::numbers::e));
  }
  EXPECT_NEAR(log_partition(2.0, kInf), 0.5 * std::log(2.0 * std::numbers::pi), 1e-10);
  EXPECT_NEAR(log_partition(0.0, kInf), std::log(std::numbers::pi * std::sqrt(2.0)), 1e-10);
  // Pseudo-Huber: Z = 2 e K_1(1).
  EXPECT_NEAR(log_partition(1.0, kInf), std::log(2.0 * std::numbers::e * std::cyl_bessel_k(1.0, 1.0)), 1e-10);
  // Heavy tail just above zero and beyond 2 still integrate on the infinite range.
  EXPECT_NEAR(log_partition(1e-9, kInf), log_partition(0.0, kInf), 1e-6);
  EXPECT_TRUE(std::isfinite(log_partition(0.1, kInf)));
  EXPECT_GT(log_partition(0.1, kInf), log_partition(0.2, kInf));  // heavier tail, more mass
}

TEST(LogPartition, GrowsWithTauAndIsMonotoneInAlpha) {
  for (double a : {-10.0, -2.0, 0.0, 1.0})
    EXPECT_LT(log_partition(a, 5.0), log_partition(a, 10.0)) << a;
  for (double a = -10.0; a < 2.0; a += 0.5) EXPECT_GT(log_partition(a, 10.0), log_partition(a + 0.5, 10.0)) << a;
}

TEST(LogPartition, RejectsDivergentAndInvalidInput) {
  EXPECT_THROW(log_partition(-0.1, kInf), std::invalid_argument);
  EXPECT_THROW(log_partition(1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(log_partition(1.0, std::nan("")), std::invalid_argument);
  EXPECT_THROW(LogPartitionTable{kInf}, std::invalid_argument);
  EXPECT_THROW(LogPartitionTable(5.0, -10.0, 2.0, 0.0), std::invalid_argument);
  EXPECT_THROW(LogPartitionTable(5.0, 2.0, -10.0, 0.1), std::invalid_argument);
}

TEST(LogPartitionTable, GridAndLookup) {
  const LogPartitionTable table(5.0);
  ASSERT_EQ(table.alphas().size(), 121u);
  ASSERT_EQ(table.log_z().size(), 121u);
  EXPECT_EQ(table.tau(), 5.0);
  EXPECT_EQ(table.alphas().front(), -10.0);
  EXPECT_EQ(table.alphas().back(), 2.0);  // exactly, no drift
  EXPECT_EQ(table.alphas()[100], 0.0);
  EXPECT_EQ(table.alphas()[1], -9.9);
  EXPECT_EQ(table.alphas()[110], 1.0);
  for (std::size_t k = 0; k < table.alphas().size(); ++k)
    EXPECT_DOUBLE_EQ(table.log_z()[k], log_partition(table.alphas()[k], 5.0));
  for (const Reference& r : kDesignTable) {
    if (r.tau == 5.0) {
      EXPECT_NEAR(table.at(r.alpha), r.log_z, 1e-5) << r.alpha;
    }
  }
  EXPECT_EQ(table.at(0.96), table.at(1.0));  // nearest grid point
  EXPECT_EQ(table.at(1.04), table.at(1.0));
  EXPECT_EQ(table.at(-10.04), table.at(-10.0));
  EXPECT_THROW(table.at(2.2), std::out_of_range);
  EXPECT_THROW(table.at(-10.2), std::out_of_range);
  EXPECT_THROW(table.at(std::nan("")), std::out_of_range);
}

TEST(LogPartitionTable, InfiniteTauForNonNegativeGrid) {
  const LogPartitionTable table(kInf, 0.0, 2.0, 0.5);
  ASSERT_EQ(table.alphas().size(), 5u);
  EXPECT_NEAR(table.at(0.0), std::log(std::numbers::pi * std::sqrt(2.0)), 1e-10);
  EXPECT_NEAR(table.at(2.0), 0.5 * std::log(2.0 * std::numbers::pi), 1e-10);
}

}  // namespace
}  // namespace varslam::robust
