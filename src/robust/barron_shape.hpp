#pragma once
// Internal: Barron's loss on the normalised squared residual q = (x/c)^2, shared by the loss, the
// partition integral and the alpha sweep. Not part of the public API.
#include <cmath>

namespace varslam::robust::detail {

enum class Shape { L2, Cauchy, Welsch, General };

// Within this distance of 0 or 2 the limit is used: there the truncation error of the limit
// (~1e-12 * log^2(1 + q)) is far below double-precision noise of the general formula.
inline constexpr double kLimitEps = 1e-12;

inline Shape shape_of(double alpha) {
  if (alpha <= -1e3) return Shape::Welsch;  // kWelschAlpha, also catches -inf
  if (std::abs(alpha) < kLimitEps) return Shape::Cauchy;
  if (std::abs(alpha - 2.0) < kLimitEps) return Shape::L2;
  return Shape::General;
}

/// One shape alpha with its constants precomputed, evaluated on q = (x/c)^2 with c = 1.
struct ShapeParams {
  Shape shape;
  double alpha;
  double b;         // |alpha - 2|
  double inv_b;     // 1 / b
  double b_over_a;  // b / alpha
  double half_a;    // alpha / 2

  explicit ShapeParams(double a)
      : shape(shape_of(a)),
        alpha(a),
        b(std::abs(a - 2.0)),
        inv_b(1.0 / b),
        b_over_a(b / a),
        half_a(0.5 * a) {}

  /// rho as a function of q = z^2 (expm1/log1p keep it accurate near q = 0 and near alpha = 0).
  double rho(double q) const {
    switch (shape) {
      case Shape::L2: return 0.5 * q;
      case Shape::Cauchy: return std::log1p(0.5 * q);
      case Shape::Welsch: return -std::expm1(-0.5 * q);
      case Shape::General: break;
    }
    return b_over_a * std::expm1(half_a * std::log1p(q * inv_b));
  }

  /// rho(z) and d^2 rho / dz^2 at z with z^2 = q: rho''(z) = u^(a/2-2) (u + (a-2) z^2 / b),
  /// u = 1 + z^2 / b. Used for the second-order bin correction of the alpha sweep.
  void rho_and_d2z(double q, double& r, double& d2) const {
    switch (shape) {
      case Shape::L2: r = 0.5 * q; d2 = 1.0; return;
      case Shape::Cauchy: {
        const double u = 1.0 + 0.5 * q;
        r = std::log1p(0.5 * q);
        d2 = (u - q) / (u * u);
        return;
      }
      case Shape::Welsch: {
        const double e = std::exp(-0.5 * q);
        r = 1.0 - e;
        d2 = e * (1.0 - q);
        return;
      }
      case Shape::General: break;
    }
    const double u = 1.0 + q * inv_b;
    const double em = std::expm1(half_a * std::log1p(q * inv_b));  // u^(a/2) - 1
    r = b_over_a * em;
    d2 = (em + 1.0) / (u * u) * (u + (alpha - 2.0) * q * inv_b);
  }
};

}  // namespace varslam::robust::detail
