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

BarronKernel::BarronKernel(double alpha, double c) : alpha_(alpha), c_(c) {
  const double c2 = c * c;
  two_c2_ = 2.0 * c2;
  half_a_ = 0.5 * alpha;
  switch (detail::shape_of(alpha)) {
    case Shape::L2: form_ = Form::L2; break;
    case Shape::Cauchy: form_ = Form::Cauchy; break;
    case Shape::Welsch: form_ = Form::Welsch; break;
    case Shape::General:
      form_ = std::abs(alpha - 1.0) < detail::kLimitEps ? Form::PseudoHuber : Form::General;
      break;
  }
  // Constants of the limits: b = 1 for pseudo-Huber, 2 for Cauchy (and Welsch's exp(-q/2)).
  const double b = form_ == Form::PseudoHuber ? 1.0 : form_ == Form::General ? std::abs(alpha - 2.0) : 2.0;
  inv_bc2_ = 1.0 / (b * c2);
  value_scale_ = form_ == Form::General ? two_c2_ * b / alpha : 0.0;
  // kernel'' = (a/2 - 1) u^(a/2-2) / (c^2 b) = sign(a - 2) u^(a/2-2) / (2 c^2), since b = |a - 2|.
  d2_scale_ = (alpha < 2.0 ? -1.0 : 1.0) / two_c2_;
}

void barron_kernel(double s, double alpha, double c, double out[3]) { BarronKernel(alpha, c).evaluate(s, out); }

}  // namespace varslam::robust
