#pragma once
// Barron's general adaptive robust loss ("A General and Adaptive Robust Loss Function", CVPR 2019):
// the loss, its IRLS weight, the kernel form on squared errors used by solvers, the truncated
// log-partition table and the grid-search estimate of the shape alpha. Pure math, no SLAM types.
//
// Conventions (DESIGN.md section 2):
//  - barron_rho is the paper's loss, a function of x/c only: rho(x; a, c) = rho(x/c; a, 1), so
//    rho(x; 2, c) = (x/c)^2 / 2. It is the negative log-density used by estimate_alpha.
//  - barron_kernel is the solver form on s = x^2: kernel(s) = 2 c^2 rho(sqrt(s); a, c), hence
//    kernel(s) ~ s for small s and kernel'(0) = 1 (the ceres::LossFunction convention).
//    With c = 1 (whitened residuals, the paper's choice) this is kernel(s) = 2 rho(sqrt(s)).
//    Consequences: alpha = 1 gives kernel(s) = 2 * pseudo-Huber(sqrt(s), delta = c) exactly, i.e.
//    c^2 * rho(x; 1, c) = c^2 (sqrt(1 + (x/c)^2) - 1); alpha = 0 gives 2 c^2 log(1 + s / (2 c^2)).
//  - barron_weight(x) = rho'(x) / x = kernel'(x^2) / c^2.
//  - Shapes: any finite alpha works (alpha > 2 included); alpha = 0 and alpha = 2 use their limits;
//    alpha <= kWelschAlpha (or -infinity) is the Welsch limit a -> -inf.
#include <cmath>
#include <span>
#include <vector>

namespace varslam::robust {

/// At or below this alpha the loss is the Welsch limit 1 - exp(-(x/c)^2 / 2) (at -1e3 the general
/// formula differs from it by O(1/|alpha|), below anything a grid search could see).
inline constexpr double kWelschAlpha = -1e3;

/// rho(x; alpha, c) on a residual x (any sign). alpha = 2 is L2, 0 Cauchy, 1 pseudo-Huber,
/// alpha <= -1e3 (or -infinity) Welsch. Exact at the special shapes.
double barron_rho(double x, double alpha, double c);
/// IRLS weight rho'(x)/x.
double barron_weight(double x, double alpha, double c);

/// Kernel on a squared whitened error s = e^T Omega e: out = {rho(s), rho'(s), rho''(s)} in the
/// convention of ceres::LossFunction (rho(s) ~ s for small s): kernel(s) = 2 c^2 barron_rho(sqrt(s)).
/// One-off convenience: solvers evaluating many residuals at one alpha should hold a BarronKernel.
void barron_kernel(double s, double alpha, double c, double out[3]);

/// barron_kernel for one shape alpha and scale c, with every constant that depends only on (alpha, c)
/// precomputed: build it once per solve (or per alpha change), evaluate it per residual.
/// Per evaluation: alpha = 2 plain arithmetic, alpha = 1 one sqrt, alpha = 0 one log1p, the Welsch limit
/// one exp, any other alpha one log1p plus one exp or expm1 (the cost of one pow, measured, but exact
/// near s = 0 where a pow-based u^(a/2) - 1 cancels). The special shapes are taken within 1e-12 of
/// 0, 1 and 2, where they equal the general formula to double precision.
class BarronKernel {
 public:
  explicit BarronKernel(double alpha, double c = 1.0);
  double alpha() const { return alpha_; }
  double c() const { return c_; }

  /// out = {kernel(s), kernel'(s), kernel''(s)}, s >= 0.
  void evaluate(double s, double out[3]) const {
    switch (form_) {
      case Form::L2:
        out[0] = s;
        out[1] = 1.0;
        out[2] = 0.0;
        return;
      case Form::PseudoHuber: {
        // u = 1 + q: kernel = 2 c^2 (sqrt(u) - 1) = 2 s / (sqrt(u) + 1) (no cancellation at small s),
        // kernel' = u^(-1/2), kernel'' = -u^(-3/2) / (2 c^2).
        const double r = std::sqrt(1.0 + s * inv_bc2_);
        const double inv_r = 1.0 / r;
        out[0] = 2.0 * s / (r + 1.0);
        out[1] = inv_r;
        out[2] = d2_scale_ * inv_r * inv_r * inv_r;
        return;
      }
      case Form::Cauchy: {
        // u = 1 + q / 2: kernel = 2 c^2 log(u), kernel' = 1 / u, kernel'' = -1 / (2 c^2 u^2).
        const double t = s * inv_bc2_;
        const double inv_u = 1.0 / (1.0 + t);
        out[0] = two_c2_ * std::log1p(t);
        out[1] = inv_u;
        out[2] = d2_scale_ * inv_u * inv_u;
        return;
      }
      case Form::Welsch: {
        // Rare shape: a division keeps exp's argument correctly rounded (it amplifies argument errors).
        const double x = -s / two_c2_;
        const double e = std::exp(x);
        // 1 - e cancels only for small arguments; there expm1 keeps the value exact.
        out[0] = e > 0.5 ? -two_c2_ * std::expm1(x) : two_c2_ * (1.0 - e);
        out[1] = e;
        out[2] = d2_scale_ * e;
        return;
      }
      case Form::General: break;
    }
    // u = 1 + q / b; w = u^(a/2) = exp(a/2 log u). kernel = 2 c^2 (b/a) (w - 1), kernel' = w / u,
    // kernel'' = sign(a - 2) w / (2 c^2 u^2). w - 1 is taken from expm1 where it would cancel.
    const double t = s * inv_bc2_;
    const double h = half_a_ * std::log1p(t);
    double w, w_minus_1;
    if (std::abs(h) < 0.4) {
      w_minus_1 = std::expm1(h);
      w = w_minus_1 + 1.0;
    } else {
      w = std::exp(h);
      w_minus_1 = w - 1.0;
    }
    const double inv_u = 1.0 / (1.0 + t);
    out[0] = value_scale_ * w_minus_1;
    out[1] = w * inv_u;
    out[2] = d2_scale_ * out[1] * inv_u;
  }

 private:
  enum class Form : unsigned char { L2, PseudoHuber, Cauchy, Welsch, General };
  Form form_;
  double alpha_, c_;
  double inv_bc2_;      // 1 / (b c^2), b = |alpha - 2| (1 for pseudo-Huber, 2 for Cauchy and Welsch)
  double two_c2_;       // 2 c^2
  double value_scale_;  // 2 c^2 b / alpha
  double half_a_;       // alpha / 2
  double d2_scale_;     // sign(alpha - 2) / (2 c^2)
};

/// log Z(alpha) with Z = integral over [-tau, tau] of exp(-rho(x; alpha, 1)) dx (tau = +inf allowed for
/// alpha >= 0), tabulated once on a grid of alpha.
class LogPartitionTable {
 public:
  /// Grid alpha_k = alpha_min + k * step (k = 0..round((alpha_max - alpha_min) / step)), each value
  /// rounded to 1e-12 so that decimal grid points (0, 2, -9.9, ...) are exactly the nearest double.
  /// Throws std::invalid_argument for tau <= 0, step <= 0, alpha_max < alpha_min, or tau = inf with
  /// alpha_min < 0 (Z diverges).
  LogPartitionTable(double tau, double alpha_min = -10.0, double alpha_max = 2.0, double step = 0.1);
  double tau() const { return tau_; }
  const std::vector<double>& alphas() const { return alphas_; }
  const std::vector<double>& log_z() const { return log_z_; }
  /// Value at a grid alpha (nearest grid point); throws std::out_of_range outside the grid.
  double at(double alpha) const;

 private:
  double tau_;
  double alpha_min_;
  double step_;
  std::vector<double> alphas_;
  std::vector<double> log_z_;
};

/// Numerically integrated log Z(alpha) for one alpha (used to build the table and in tests).
/// Adaptive Gauss-Legendre; absolute error well below 1e-9. Throws std::invalid_argument for
/// tau <= 0 or NaN, and for tau = inf with alpha < 0.
double log_partition(double alpha, double tau);

/// How residuals enter the likelihood.
enum class AlphaFit {
  ResidualNorm,  // the paper: one sample per residual, its whitened norm
  PerComponent,  // each whitened component is a sample: no bias toward alpha < 2 on Gaussian noise
};

/// Turns stacked whitened residual vectors (dims components each, e.g. 2 for monocular, 3 for RGB-D
/// "virtual stereo") into samples for estimate_alpha: the components themselves (PerComponent) or
/// one Euclidean norm per residual (ResidualNorm). Throws std::invalid_argument if dims < 1 or the
/// size is not a multiple of dims.
std::vector<double> samples_from_residuals(std::span<const double> whitened_components, int dims,
                                           AlphaFit fit);

struct AlphaEstimate {
  double alpha = 2.0;
  double nll = 0.0;  // negative log-likelihood at alpha (sum over samples)
};

/// Grid search of alpha minimising sum_i [log Z(alpha) + rho(x_i; alpha, c)] over the table's grid.
/// Samples beyond tau are clamped to tau (the truncated density has no mass outside); the clamp acts
/// on x/c, since the table is built for c = 1. Deterministic. Returns {alphas().back(), 0} for no samples.
/// Speed: the samples are binned on log(1 + |x|/c) (bin width 0.03) and each bin contributes
/// n rho(mean) + rho''(mean) * sum (x - mean)^2 / 2, so the sweep costs (#bins x #alphas) instead of
/// (#samples x #alphas) transcendental calls (10k samples: ~0.4-0.7 ms instead of ~33 ms). The NLL error
/// of that sweep is below 1e-7 per sample (measured, see tests: 1e-3 on 10k samples, far below the
/// NLL gap between neighbouring grid alphas); the returned nll is recomputed exactly at the chosen alpha.
AlphaEstimate estimate_alpha(std::span<const double> samples, const LogPartitionTable& table, double c = 1.0);

/// The binned NLL of estimate_alpha at every grid alpha (same order as table.alphas()), for diagnostics
/// and experiments. All zeros for no samples. Throws std::invalid_argument for c <= 0 or a NaN sample.
std::vector<double> alpha_nll_curve(std::span<const double> samples, const LogPartitionTable& table, double c = 1.0);

}  // namespace varslam::robust
