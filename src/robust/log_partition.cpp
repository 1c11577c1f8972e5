// Truncated log-partition log Z(alpha, tau) by adaptive Gauss-Legendre quadrature, and its table.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "robust/barron.hpp"
#include "robust/barron_shape.hpp"

namespace varslam::robust {

namespace {

constexpr int kNodes = 10;  // exact for polynomials up to degree 19 per panel

struct GaussLegendre {
  std::array<double, kNodes> x{};  // nodes on [-1, 1]
  std::array<double, kNodes> w{};
};

// Nodes are the roots of P_n, found by Newton from the Chebyshev guess cos(pi (i + 3/4) / (n + 1/2));
// weights 2 / ((1 - x^2) P_n'(x)^2).
GaussLegendre make_gauss_legendre() {
  GaussLegendre g;
  for (int i = 0; i < kNodes; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (kNodes + 0.5));
    double dp = 0.0;
    for (int iter = 0; iter < 100; ++iter) {
      double p0 = 1.0, p1 = x;  // P_0, P_1
      for (int k = 2; k <= kNodes; ++k) {
        const double pk = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = pk;
      }
      dp = kNodes * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    g.x[i] = x;
    g.w[i] = 2.0 / ((1.0 - x * x) * dp * dp);
  }
  return g;
}

const GaussLegendre& gauss_legendre() {
  static const GaussLegendre g = make_gauss_legendre();
  return g;
}

template <class F>
double panel(const F& f, double lo, double hi) {
  const GaussLegendre& g = gauss_legendre();
  const double half = 0.5 * (hi - lo), mid = 0.5 * (hi + lo);
  double sum = 0.0;
  for (int i = 0; i < kNodes; ++i) sum += g.w[i] * f(mid + half * g.x[i]);
  return half * sum;
}

// Bisect until one panel and its two halves agree to tol (the halves are then much better than tol).
template <class F>
double adaptive(const F& f, double lo, double hi, double whole, double tol, int depth) {
  const double mid = 0.5 * (lo + hi);
  const double left = panel(f, lo, mid), right = panel(f, mid, hi);
  if (depth >= 40 || std::abs(left + right - whole) <= tol) return left + right;
  return adaptive(f, lo, mid, left, 0.5 * tol, depth + 1) + adaptive(f, mid, hi, right, 0.5 * tol, depth + 1);
}

template <class F>
double integrate(const F& f, double lo, double hi) {
  return adaptive(f, lo, hi, panel(f, lo, hi), 1e-13, 0);
}

}  // namespace

double log_partition(double alpha, double tau) {
  if (!(tau > 0.0))
    throw std::invalid_argument("log_partition: tau must be > 0, got " + std::to_string(tau));
  const bool infinite = std::isinf(tau);
  if (infinite && alpha < 0.0)
    throw std::invalid_argument("log_partition: Z diverges for tau = inf and alpha = " + std::to_string(alpha) +
                                " < 0; use a finite tau");
  const detail::ShapeParams p(alpha);
  const auto density = [&p](double x) { return std::exp(-p.rho(x * x)); };
  // Z = 2 * integral over [0, tau] (rho is even). Split at 1 so the core and the tail get their own panels.
  double half_z = integrate(density, 0.0, std::min(tau, 1.0));
  if (infinite) {
    // x = 1/t maps [1, inf) onto (0, 1]; exp(-rho + 2 log x) avoids 0 * inf when rho overflows.
    const auto tail = [&p](double t) {
      const double x = 1.0 / t;
      return std::exp(-p.rho(x * x) + 2.0 * std::log(x));
    };
    half_z += integrate(tail, 0.0, 1.0);
  } else if (tau > 1.0) {
    half_z += integrate(density, 1.0, tau);
  }
  return std::log(2.0 * half_z);
}

LogPartitionTable::LogPartitionTable(double tau, double alpha_min, double alpha_max, double step)
    : tau_(tau), alpha_min_(alpha_min), step_(step) {
  if (!(tau > 0.0)) throw std::invalid_argument("LogPartitionTable: tau must be > 0");
  if (!(step > 0.0)) throw std::invalid_argument("LogPartitionTable: step must be > 0");
  if (!(alpha_max >= alpha_min)) throw std::invalid_argument("LogPartitionTable: alpha_max < alpha_min");
  if (std::isinf(tau) && alpha_min < 0.0)
    throw std::invalid_argument("LogPartitionTable: tau = inf needs alpha_min >= 0 (Z diverges for alpha < 0)");
  const long count = std::lround((alpha_max - alpha_min) / step) + 1;
  alphas_.reserve(static_cast<std::size_t>(count));
  log_z_.reserve(static_cast<std::size_t>(count));
  for (long k = 0; k < count; ++k) {
    // alpha_min + k * step has no accumulated drift; rounding to 1e-12 turns 2.0000000000000036 into 2.
    const double a = std::round((alpha_min + static_cast<double>(k) * step) * 1e12) / 1e12;
    alphas_.push_back(a);
    log_z_.push_back(log_partition(a, tau));
  }
}

double LogPartitionTable::at(double alpha) const {
  const double k = std::round((alpha - alpha_min_) / step_);
  if (!(k >= 0.0 && k < static_cast<double>(alphas_.size())))
    throw std::out_of_range("LogPartitionTable::at: alpha " + std::to_string(alpha) + " outside the grid [" +
                            std::to_string(alphas_.front()) + ", " + std::to_string(alphas_.back()) + "]");
  return log_z_[static_cast<std::size_t>(k)];
}

}  // namespace varslam::robust
