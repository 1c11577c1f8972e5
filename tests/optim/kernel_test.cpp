#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "optim/kernel.hpp"

namespace varslam::optim {
namespace {

KernelConfig config(KernelType type, double alpha = 1.0) {
  KernelConfig k;
  k.type = type;
  k.barron_alpha = alpha;
  return k;
}

TEST(Kernel, HuberIsQuadraticInsideTheGateAndLinearInNormOutside) {
  const KernelConfig k = config(KernelType::Huber);
  double out[3];
  evaluate_kernel(k, 2.0, 2, 4.0, out);
  EXPECT_DOUBLE_EQ(out[0], 4.0);
  EXPECT_DOUBLE_EQ(out[1], 1.0);
  // Outside: rho(s) = 2 delta sqrt(s) - delta^2 with delta^2 = 5.991 (mono) / 7.815 (stereo).
  for (int dof : {2, 3}) {
    const double d2 = dof == 2 ? 5.991 : 7.815;
    evaluate_kernel(k, 2.0, dof, 100.0, out);
    EXPECT_NEAR(out[0], 2 * std::sqrt(d2) * 10.0 - d2, 1e-12);
    EXPECT_NEAR(out[1], std::sqrt(d2) / 10.0, 1e-12);
    // Continuous at the threshold.
    double below[3], above[3];
    evaluate_kernel(k, 2.0, dof, d2 * (1 - 1e-9), below);
    evaluate_kernel(k, 2.0, dof, d2 * (1 + 1e-9), above);
    EXPECT_NEAR(below[0], above[0], 1e-6);
    EXPECT_NEAR(below[1], above[1], 1e-6);
  }
}

TEST(Kernel, BarronAlphaTwoIsLeastSquaresAndAlphaOneIsPseudoHuber) {
  double l2[3], b2[3], b1[3];
  for (double s : {0.01, 1.0, 30.0}) {
    evaluate_kernel(config(KernelType::None), 2.0, 2, s, l2);
    evaluate_kernel(config(KernelType::BarronFixed, 2.0), 2.0, 2, s, b2);
    EXPECT_NEAR(b2[0], l2[0], 1e-9 * (1 + s));
    EXPECT_NEAR(b2[1], 1.0, 1e-9);
    // alpha = 1, c = 1: rho(s) = 2 (sqrt(1 + s) - 1), rho'(s) = 1 / sqrt(1 + s).
    evaluate_kernel(config(KernelType::BarronFixed, 1.0), 1.0, 2, s, b1);
    EXPECT_NEAR(b1[0], 2 * (std::sqrt(1 + s) - 1), 1e-9 * (1 + s));
    EXPECT_NEAR(b1[1], 1 / std::sqrt(1 + s), 1e-9);
  }
}

TEST(Kernel, LossUsesTheSameCodeAndFollowsAlpha) {
  const KernelConfig k = config(KernelType::BarronAdaptive, 1.0);
  std::unique_ptr<KernelLoss> loss(make_loss(k, 3, 1.0));
  ASSERT_TRUE(loss);
  double a[3], b[3];
  loss->Evaluate(9.0, a);
  evaluate_kernel(k, 1.0, 3, 9.0, b);
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(a[i], b[i]);
  loss->set_alpha(-2.0);
  loss->Evaluate(9.0, a);
  EXPECT_LT(a[1], b[1]);  // a lower alpha down-weights a large error more
  EXPECT_EQ(make_loss(config(KernelType::None), 2, 2.0), nullptr);
}

TEST(Kernel, AlphaFitDropsWithOutliers) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> wild(-40.0, 40.0);
  KernelConfig k = config(KernelType::BarronAdaptive);
  k.fit = robust::AlphaFit::PerComponent;
  AlphaSamples clean(k.fit), dirty(k.fit);
  for (int i = 0; i < 2000; ++i) {
    const double e[2] = {n01(rng), n01(rng)};
    clean.add(e);
    const double f[2] = {i % 3 == 0 ? wild(rng) : e[0], i % 3 == 0 ? wild(rng) : e[1]};
    dirty.add(f);
  }
  EXPECT_EQ(clean.samples().size(), 4000u);
  const double a_clean = fit_alpha(k, clean.samples(), 1.0).applied;
  const double a_dirty = fit_alpha(k, dirty.samples(), 1.0).applied;
  EXPECT_GT(a_clean, 1.5);  // per-component samples of Gaussian noise: close to L2
  EXPECT_LT(a_dirty, a_clean - 1.0);
  EXPECT_DOUBLE_EQ(fit_alpha(k, {}, 0.7).applied, 0.7);  // no samples: keep the current alpha
  // A cap keeps the fit from going less robust than alpha_max; below it the fit is untouched.
  k.alpha_max = 1.0;
  EXPECT_DOUBLE_EQ(fit_alpha(k, clean.samples(), 1.0).applied, 1.0);
  EXPECT_DOUBLE_EQ(fit_alpha(k, clean.samples(), 1.0).fitted, a_clean);  // the fit itself is reported uncapped
  EXPECT_DOUBLE_EQ(fit_alpha(k, dirty.samples(), 1.0).applied, std::min(1.0, a_dirty));
}

TEST(Kernel, ResidualNormSamplesAreNorms) {
  AlphaSamples s(robust::AlphaFit::ResidualNorm);
  const double e[3] = {3.0, 0.0, 4.0};
  s.add(e);
  ASSERT_EQ(s.samples().size(), 1u);
  EXPECT_DOUBLE_EQ(s.samples()[0], 5.0);
}

}  // namespace
}  // namespace varslam::optim
