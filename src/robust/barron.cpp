// Barron's loss, IRLS weight and solver kernel (conventions in barron.hpp).
#include "robust/barron.hpp"

#include <cmath>

#include "robust/barron_shape.hpp"

namespace varslam::robust {

using detail::Shape;
using detail::ShapeParams;

double barron_rho(double x, double alpha, double c) {
  const double z = x / c;
  return ShapeParams(alpha).rho(z * z);
}

namespace {

// kernel'(s) = u^(a/2-1) with u = 1 + q/b, q = s/c^2: the factor every robust solver reweights by.
double kernel_d1(const ShapeParams& p, double q) {
  switch (p.shape) {
    case Shape::L2: return 1.0;
    case Shape::Cauchy: return 1.0 / (1.0 + 0.5 * q);
    case Shape::Welsch: return std::exp(-0.5 * q);
    case Shape::General: break;
  }
  return std::exp((p.half_a - 1.0) * std::log1p(q * p.inv_b));
}

}  // namespace

double barron_weight(double x, double alpha, double c) {
  const double z = x / c;
  return kernel_d1(ShapeParams(alpha), z * z) / (c * c);
}

void barron_kernel(double s, double alpha, double c, double out[3]) {
  const ShapeParams p(alpha);
  const double c2 = c * c;
  const double q = s / c2;
  out[0] = 2.0 * c2 * p.rho(q);
  // kernel'' = (a/2 - 1) u^(a/2-2) / (c^2 b) = sign(a - 2) u^(a/2-2) / (2 c^2), since b = |a - 2|.
  switch (p.shape) {
    case Shape::L2:
      out[1] = 1.0;
      out[2] = 0.0;
      return;
    case Shape::Cauchy: {
      const double inv_u = 1.0 / (1.0 + 0.5 * q);
      out[1] = inv_u;
      out[2] = -inv_u * inv_u / (2.0 * c2);
      return;
    }
    case Shape::Welsch: {
      const double e = std::exp(-0.5 * q);
      out[1] = e;
      out[2] = -e / (2.0 * c2);
      return;
    }
    case Shape::General: break;
  }
  const double log_u = std::log1p(q * p.inv_b);
  out[1] = std::exp((p.half_a - 1.0) * log_u);
  const double d2 = std::exp((p.half_a - 2.0) * log_u) / (2.0 * c2);
  out[2] = alpha < 2.0 ? -d2 : d2;
}

}  // namespace varslam::robust
