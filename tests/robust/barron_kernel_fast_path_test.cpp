// BarronKernel: the precomputed-shape evaluator the solvers use. Its fast paths (alpha = 1, 2, 0, Welsch) must
// be the general formula, not an approximation of it.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "robust/barron.hpp"

namespace varslam::robust {
namespace {

const std::vector<double> kSquaredErrors = {0.0, 1e-10, 1e-4, 0.05, 0.7, 1.0, 3.2, 7.8, 25.0, 400.0, 1e5};

// The general formula in long double, straight from DESIGN.md: kernel(s) = 2 c^2 (b/a) (u^(a/2) - 1),
// kernel' = u^(a/2-1), kernel'' = (a/2 - 1) u^(a/2-2) / (b c^2), u = 1 + s / (b c^2). Only for a != 0, 2.
void reference_kernel(double s, double alpha, double c, long double out[3]) {
  const long double a = alpha, c2 = static_cast<long double>(c) * c, b = std::fabs(a - 2.0L);
  const long double t = s / (b * c2), log_u = std::log1p(t), u = 1.0L + t;
  out[0] = 2.0L * c2 * b / a * std::expm1(a / 2.0L * log_u);
  out[1] = std::exp((a / 2.0L - 1.0L) * log_u);
  out[2] = (a / 2.0L - 1.0L) * std::exp((a / 2.0L - 2.0L) * log_u) / (b * c2);
  (void)u;
}

double rel_err(double x, long double ref) {
  return static_cast<double>(std::fabs(static_cast<long double>(x) - ref) / std::fmax(std::fabs(ref), 1e-300L));
}

TEST(BarronKernelFastPath, AlphaOneEqualsTheGeneralFormula) {
  for (double c : {0.5, 1.0, 2.0})
    for (double s : kSquaredErrors) {
      if (s == 0.0) continue;
      double k[3];
      long double ref[3];
      BarronKernel(1.0, c).evaluate(s, k);
      reference_kernel(s, 1.0, c, ref);
      for (int i = 0; i < 3; ++i) EXPECT_LT(rel_err(k[i], ref[i]), 1e-14) << "i=" << i << " s=" << s << " c=" << c;
    }
}

TEST(BarronKernelFastPath, GeneralPathMatchesLongDoubleReference) {
  // The general path itself (log1p + exp/expm1) is exact to a few ulps at any shape, also near 0 and 2.
  for (double a : {-10.0, -2.0, -0.5, -1e-6, 1e-6, 0.3, 0.999, 1.001, 1.7, 2.0 - 1e-6, 2.0 + 1e-6, 3.0})
    for (double c : {0.7, 1.0})
      for (double s : kSquaredErrors) {
        if (s == 0.0) continue;
        double k[3];
        long double ref[3];
        BarronKernel(a, c).evaluate(s, k);
        reference_kernel(s, a, c, ref);
        for (int i = 0; i < 3; ++i) {
          if (std::fabs(ref[i]) < 1e-280L) continue;  // underflow of the weight of a huge error at a = -10
          EXPECT_LT(rel_err(k[i], ref[i]), 1e-12) << "i=" << i << " a=" << a << " s=" << s << " c=" << c;
        }
      }
}

// Around each special shape the fast path must equal the midpoint of the general path just below and just
// above it (the midpoint cancels the first-order change in alpha; the second-order term is ~1e-16 here).
TEST(BarronKernelFastPath, SpecialShapesEqualTheGeneralFormulaAroundThem) {
  const double d = 1e-8;
  for (double a0 : {0.0, 1.0, 2.0})
    for (double c : {0.5, 1.0, 3.0})
      for (double s : kSquaredErrors) {
        double at[3], lo[3], hi[3];
        BarronKernel(a0, c).evaluate(s, at);
        BarronKernel(a0 - d, c).evaluate(s, lo);
        BarronKernel(a0 + d, c).evaluate(s, hi);
        // At a = 2, kernel'' jumps between -1/(2c^2) and +1/(2c^2) where s << |a - 2| (a real discontinuity
        // of the family, see BarronRho.ContinuousAtSpecialShapes): compare it only where it is continuous.
        const int checked = a0 == 2.0 ? 2 : 3;
        for (int i = 0; i < checked; ++i) {
          const double mid = 0.5 * (lo[i] + hi[i]);
          EXPECT_NEAR(at[i], mid, 1e-12 * std::abs(mid) + 1e-300)
              << "i=" << i << " a=" << a0 << " s=" << s << " c=" << c;
        }
      }
}

TEST(BarronKernelFastPath, NearSpecialShapesTheFastPathIsTaken) {
  // Within 1e-12 of 1 the pseudo-Huber path answers, and agrees with the general formula at 1 +- 1e-12.
  double k[3], g[3];
  BarronKernel(1.0 + 5e-13).evaluate(9.0, k);
  EXPECT_DOUBLE_EQ(k[0], 2.0 * (std::sqrt(10.0) - 1.0));
  BarronKernel(1.0 + 2e-12).evaluate(9.0, g);  // general path
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(k[i], g[i], 1e-11 * std::abs(g[i]));
}

TEST(BarronKernelFastPath, FreeFunctionAndObjectAgree) {
  for (double a : {-1e4, -6.0, 0.0, 0.5, 1.0, 2.0, 4.0})
    for (double s : kSquaredErrors) {
      double f[3], o[3];
      barron_kernel(s, a, 1.3, f);
      BarronKernel(a, 1.3).evaluate(s, o);
      for (int i = 0; i < 3; ++i) EXPECT_EQ(f[i], o[i]);
    }
  const BarronKernel k(-3.0, 2.0);
  EXPECT_EQ(k.alpha(), -3.0);
  EXPECT_EQ(k.c(), 2.0);
}

TEST(BarronKernelFastPath, SmallErrorsKeepFullRelativePrecision) {
  // kernel(s) ~ s for s -> 0 at every shape: no cancellation in the value (u^(a/2) - 1, sqrt(u) - 1).
  for (double a : {-10.0, -1.0, 0.0, 0.5, 1.0, 1.5, 2.0})
    for (double s : {1e-12, 1e-9, 1e-6}) {
      double k[3];
      BarronKernel(a).evaluate(s, k);
      EXPECT_NEAR(k[0] / s, 1.0, s + 1e-15) << a << " " << s;
    }
}

}  // namespace
}  // namespace varslam::robust
