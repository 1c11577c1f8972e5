#include "synth/primitives.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace varslam::synth {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

// Slab test against [lo, hi] in the ray's frame; returns entry t and the entering axis (sign in nsign).
bool slab(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
          double t_min, double t_max, double& t_hit, int& axis, double& nsign) {
  double t0 = -kInf, t1 = kInf;
  int ax = -1;
  double sgn = 0;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-12) {
      if (o[k] < lo[k] || o[k] > hi[k]) return false;
      continue;
    }
    const double inv = 1.0 / d[k];
    double ta = (lo[k] - o[k]) * inv, tb = (hi[k] - o[k]) * inv;
    double s = -1.0;  // entering through the lo face: normal points to -k
    if (ta > tb) {
      std::swap(ta, tb);
      s = 1.0;
    }
    if (ta > t0) {
      t0 = ta;
      ax = k;
      sgn = s;
    }
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  if (ax < 0 || t0 <= t_min || t0 >= t_max) return false;  // camera inside a box: ignore that box
  t_hit = t0;
  axis = ax;
  nsign = sgn;
  return true;
}

Eigen::Vector2d face_uv(const Eigen::Vector3d& q, int axis) {
  // Two remaining axes; y (down) stays the image v so pictures stand upright.
  if (axis == 0) return {q.z(), q.y()};
  if (axis == 1) return {q.x(), q.z()};
  return {q.x(), q.y()};
}

Eigen::Vector2d wrap_uv(const Eigen::Vector3d& l, double r, double along) {
  return {(std::atan2(l.x(), l.z()) + M_PI) * r, along};
}
}  // namespace

void Primitive::bounds(Eigen::Vector3d& lo, Eigen::Vector3d& hi) const {
  switch (shape) {
    case Shape::Aabb: lo = a; hi = b; return;
    case Shape::Obb: {
      const Eigen::Vector3d e = R.cwiseAbs() * b;
      lo = a - e;
      hi = a + e;
      return;
    }
    case Shape::Sphere: lo = a.array() - radius; hi = a.array() + radius; return;
    case Shape::Capsule:
      lo = a.cwiseMin(b).array() - radius;
      hi = a.cwiseMax(b).array() + radius;
      return;
  }
}

bool intersect(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max,
               Hit& hit) {
  switch (p.shape) {
    case Shape::Aabb: {
      double t;
      int axis;
      double s;
      if (!slab(p.a, p.b, o, d, t_min, t_max, t, axis, s)) return false;
      hit.t = t;
      hit.n = Eigen::Vector3d::Zero();
      hit.n[axis] = s;
      hit.uv = face_uv(o + t * d - p.a, axis);
      hit.material = (axis == 1 && p.top_material >= 0) ? p.top_material : p.material;
      hit.object_id = p.object_id;
      return true;
    }
    case Shape::Obb: {
      const Eigen::Vector3d ol = p.R.transpose() * (o - p.a), dl = p.R.transpose() * d;
      double t;
      int axis;
      double s;
      if (!slab(-p.b, p.b, ol, dl, t_min, t_max, t, axis, s)) return false;
      hit.t = t;
      Eigen::Vector3d nl = Eigen::Vector3d::Zero();
      nl[axis] = s;
      hit.n = p.R * nl;
      hit.uv = face_uv(ol + t * dl + p.b, axis);
      hit.material = (axis == 1 && p.top_material >= 0) ? p.top_material : p.material;
      hit.object_id = p.object_id;
      return true;
    }
    case Shape::Sphere: {
      const Eigen::Vector3d oc = o - p.a;
      const double b = oc.dot(d), c = oc.squaredNorm() - p.radius * p.radius;
      const double h = b * b - c;
      if (h < 0) return false;
      const double t = -b - std::sqrt(h);
      if (t <= t_min || t >= t_max) return false;
      const Eigen::Vector3d q = oc + t * d;
      hit.t = t;
      hit.n = q / p.radius;
      const Eigen::Vector3d l = p.R.transpose() * q;
      hit.uv = wrap_uv(l, p.radius, l.y() + p.radius);
      hit.material = p.material;
      hit.object_id = p.object_id;
      return true;
    }
    case Shape::Capsule: {
      const Eigen::Vector3d ba = p.b - p.a, oa = o - p.a;
      const double baba = ba.dot(ba), bard = ba.dot(d), baoa = ba.dot(oa), rdoa = d.dot(oa), oaoa = oa.dot(oa);
      const double qa = baba - bard * bard;
      const double qb = baba * rdoa - baoa * bard;
      const double qc = baba * oaoa - baoa * baoa - p.radius * p.radius * baba;
      double h = qb * qb - qa * qc;
      if (h < 0) return false;
      double t = qa > 1e-12 ? (-qb - std::sqrt(h)) / qa : kInf;
      const double y = baoa + t * bard;
      if (!(qa > 1e-12 && y > 0 && y < baba)) {
        // End caps: spheres at a or b.
        const Eigen::Vector3d oc = (y <= 0) ? oa : Eigen::Vector3d(o - p.b);
        const double b2 = d.dot(oc), c2 = oc.squaredNorm() - p.radius * p.radius;
        h = b2 * b2 - c2;
        if (h <= 0) return false;
        t = -b2 - std::sqrt(h);
      }
      if (t <= t_min || t >= t_max) return false;
      const Eigen::Vector3d q = oa + t * d;
      const double along = std::clamp(q.dot(ba) / baba, 0.0, 1.0);
      hit.t = t;
      hit.n = (q - along * ba).normalized();
      const Eigen::Vector3d l = p.R.transpose() * (q - along * ba);
      hit.uv = wrap_uv(l, p.radius, along * std::sqrt(baba));
      hit.material = p.material;
      hit.object_id = p.object_id;
      return true;
    }
  }
  return false;
}

double exit_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Vector3d& o,
                const Eigen::Vector3d& d, int& axis, int& side) {
  double best = kInf;
  axis = 0;
  side = 0;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-12) continue;
    const int s = d[k] > 0 ? 1 : 0;
    const double t = ((s ? hi[k] : lo[k]) - o[k]) / d[k];
    if (t < best) {
      best = t;
      axis = k;
      side = s;
    }
  }
  return best;
}

}  // namespace varslam::synth
