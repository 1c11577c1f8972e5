#pragma once
// Barron's general adaptive robust loss ("A General and Adaptive Robust Loss Function", CVPR 2019):
// the loss, its IRLS weight, the kernel form on squared errors used by solvers, the truncated
// log-partition table and the grid-search estimate of the shape alpha. Pure math, no SLAM types.
#include <span>
#include <vector>

namespace varslam::robust {

/// rho(x; alpha, c) on a residual x (any sign). alpha = 2 is L2, 0 Cauchy, 1 pseudo-Huber,
/// alpha <= -1e3 (or -infinity) Welsch. Exact at the special shapes.
double barron_rho(double x, double alpha, double c);
/// IRLS weight rho'(x)/x.
double barron_weight(double x, double alpha, double c);

/// Kernel on a squared whitened error s = e^T Omega e: out = {rho(s), rho'(s), rho''(s)} in the
/// convention of ceres::LossFunction (rho(s) ~ s for small s).
void barron_kernel(double s, double alpha, double c, double out[3]);

/// log Z(alpha) with Z = integral over [-tau, tau] of exp(-rho(x; alpha, 1)) dx (tau = +inf allowed for
/// alpha >= 0), tabulated once on a grid of alpha.
class LogPartitionTable {
 public:
  LogPartitionTable(double tau, double alpha_min = -10.0, double alpha_max = 2.0, double step = 0.1);
  double tau() const { return tau_; }
  const std::vector<double>& alphas() const { return alphas_; }
  const std::vector<double>& log_z() const { return log_z_; }
  /// Value at a grid alpha (nearest grid point); throws std::out_of_range outside the grid.
  double at(double alpha) const;

 private:
  double tau_;
  std::vector<double> alphas_;
  std::vector<double> log_z_;
};

/// Numerically integrated log Z(alpha) for one alpha (used to build the table and in tests).
double log_partition(double alpha, double tau);

/// How residuals enter the likelihood.
enum class AlphaFit {
  ResidualNorm,  // the paper: one sample per residual, its whitened norm
  PerComponent,  // each whitened component is a sample: no bias toward alpha < 2 on Gaussian noise
};

struct AlphaEstimate {
  double alpha = 2.0;
  double nll = 0.0;  // negative log-likelihood at alpha (sum over samples)
};

/// Grid search of alpha minimising sum_i [log Z(alpha) + rho(x_i; alpha, c)] over the table's grid.
/// Samples beyond tau are clamped to tau (the truncated density has no mass outside).
AlphaEstimate estimate_alpha(std::span<const double> samples, const LogPartitionTable& table, double c = 1.0);

}  // namespace varslam::robust
