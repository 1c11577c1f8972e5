#include "optim/rigid_alignment.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace varslam::optim {
namespace {

using Sample = std::array<std::size_t, 3>;

/// Inlier threshold of each correspondence: its own tolerance when given, else the global one.
class Tolerances {
 public:
  Tolerances(const std::vector<double>* per_point, double global) : per_point_(per_point), global_(global) {}
  double operator[](std::size_t i) const { return per_point_ ? (*per_point_)[i] : global_; }

 private:
  const std::vector<double>* per_point_;
  double global_;
};

/// A model's inliers and its MSAC score: sum of min(r_i^2 / tol_i^2, 1), lower is better. Truncating instead
/// of counting prefers, among models with equally many inliers, the one that fits them more tightly.
struct Consensus {
  std::vector<bool> inlier;
  int inliers = 0;
  double score = std::numeric_limits<double>::infinity();
};

Consensus evaluate(const Eigen::Isometry3d& T_ab, const std::vector<Eigen::Vector3d>& a,
                   const std::vector<Eigen::Vector3d>& b, const Tolerances& tol) {
  Consensus c;
  c.inlier.assign(a.size(), false);
  c.score = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double t = tol[i];
    const double r2 = (a[i] - T_ab * b[i]).squaredNorm();
    if (r2 < t * t) {
      c.inlier[i] = true;
      ++c.inliers;
      c.score += r2 / (t * t);
    } else {
      c.score += 1.0;
    }
  }
  return c;
}

/// Least-squares rigid fit (Umeyama, no scale) of a_i ~ T * b_i over the selected indices.
template <typename Indices>
Eigen::Isometry3d fit_rigid(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                            const Indices& indices) {
  Eigen::Matrix3Xd src(3, static_cast<Eigen::Index>(indices.size()));
  Eigen::Matrix3Xd dst(3, src.cols());
  Eigen::Index k = 0;
  for (const std::size_t i : indices) {
    src.col(k) = b[i];
    dst.col(k) = a[i];
    ++k;
  }
  return Eigen::Isometry3d(Eigen::umeyama(src, dst, false));
}

/// Weighted least-squares rigid fit (weighted Kabsch): minimises sum w_i |a_i - T b_i|^2. Used for the refit
/// with per-correspondence tolerances (w_i = 1 / tol_i^2), so that precise near points are not pulled off by
/// the noisier far ones, as an unweighted fit would.
Eigen::Isometry3d fit_rigid_weighted(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                                     const std::vector<std::size_t>& indices, const Tolerances& tol) {
  double w_sum = 0;
  Eigen::Vector3d ca = Eigen::Vector3d::Zero(), cb = Eigen::Vector3d::Zero();
  for (const std::size_t i : indices) {
    const double w = 1.0 / (tol[i] * tol[i]);
    w_sum += w;
    ca += w * a[i];
    cb += w * b[i];
  }
  ca /= w_sum;
  cb /= w_sum;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();  // sum w (a - ca)(b - cb)^T
  for (const std::size_t i : indices) cov += (1.0 / (tol[i] * tol[i])) * (a[i] - ca) * (b[i] - cb).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1;  // a rotation, not a reflection
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = svd.matrixU() * D * svd.matrixV().transpose();
  T.translation() = ca - T.linear() * cb;
  return T;
}

/// A triangle that pins down a rotation: no side too short, not close to collinear (smallest height,
/// relative to the longest side, large enough).
bool well_conditioned(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                      const RigidRansacConfig& cfg) {
  const double d01 = (p1 - p0).norm(), d12 = (p2 - p1).norm(), d20 = (p0 - p2).norm();
  if (std::min({d01, d12, d20}) < cfg.min_sample_side) return false;
  const double longest = std::max({d01, d12, d20});
  const double twice_area = (p1 - p0).cross(p2 - p0).norm();
  const double smallest_height = twice_area / longest;
  return smallest_height >= cfg.min_sample_height_ratio * longest;
}

/// Rigid motions keep distances: for two inliers, | |a_i - a_j| - |b_i - b_j| | <= tol_i + tol_j. A sample
/// violating this holds an outlier, so it is skipped without fitting (never skips an all-inlier sample).
bool distances_agree(const Sample& s, const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                     const Tolerances& tol) {
  for (int u = 0; u < 3; ++u) {
    const std::size_t i = s[static_cast<std::size_t>(u)], j = s[static_cast<std::size_t>((u + 1) % 3)];
    const double da = (a[i] - a[j]).norm(), db = (b[i] - b[j]).norm();
    if (std::abs(da - db) > tol[i] + tol[j]) return false;
  }
  return true;
}

/// Three distinct indices in [0, n). Plain modulo of the 64-bit draw: portable across standard libraries
/// (std::uniform_int_distribution is not), and its bias is negligible for n << 2^64.
Sample draw_sample(std::mt19937_64& rng, std::size_t n) {
  Sample s{};
  for (std::size_t k = 0; k < 3; ++k) {
    bool repeated = true;
    while (repeated) {
      s[k] = static_cast<std::size_t>(rng() % n);
      repeated = std::find(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(k), s[k]) !=
                 s.begin() + static_cast<std::ptrdiff_t>(k);
    }
  }
  return s;
}

/// Samples needed to draw at least one all-inlier triple with probability `confidence` at this inlier ratio.
double samples_needed(double inlier_ratio, double confidence) {
  const double p_good = inlier_ratio * inlier_ratio * inlier_ratio;
  if (p_good >= 1.0) return 0.0;
  if (p_good <= 0.0) return std::numeric_limits<double>::infinity();
  return std::log(1.0 - confidence) / std::log(1.0 - p_good);
}

std::vector<std::size_t> indices_of(const std::vector<bool>& inlier) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < inlier.size(); ++i)
    if (inlier[i]) idx.push_back(i);
  return idx;
}

/// Refits on all inliers and re-counts, while the inlier set changes and the score does not get worse.
/// `weighted`: the refit weighs each inlier by 1 / tol^2.
void refine(Eigen::Isometry3d& T_ab, Consensus& best, const std::vector<Eigen::Vector3d>& a,
            const std::vector<Eigen::Vector3d>& b, const Tolerances& tol, int iterations, bool weighted) {
  for (int it = 0; it < iterations && best.inliers >= 3; ++it) {
    const std::vector<std::size_t> idx = indices_of(best.inlier);
    const Eigen::Isometry3d T = weighted ? fit_rigid_weighted(a, b, idx, tol) : fit_rigid(a, b, idx);
    Consensus c = evaluate(T, a, b, tol);
    if (c.score > best.score) return;
    const bool changed = c.inlier != best.inlier;
    T_ab = T;
    best = std::move(c);
    if (!changed) return;
  }
}

}  // namespace

RigidRansacResult estimate_rigid_ransac(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                                        const RigidRansacConfig& cfg, const std::vector<double>* tolerance) {
  if (a.size() != b.size()) throw std::invalid_argument("estimate_rigid_ransac: a and b differ in size");
  if (tolerance && tolerance->size() != a.size())
    throw std::invalid_argument("estimate_rigid_ransac: tolerance must have one entry per correspondence");
  RigidRansacResult result;
  result.inlier.assign(a.size(), false);
  const std::size_t n = a.size();
  const int min_inliers = std::max(3, cfg.min_inliers);
  if (n < static_cast<std::size_t>(min_inliers)) return result;

  const Tolerances tol(tolerance, cfg.inlier_threshold);
  std::mt19937_64 rng(cfg.seed);
  Consensus best;
  Eigen::Isometry3d best_T = Eigen::Isometry3d::Identity();
  double needed = std::numeric_limits<double>::infinity();
  for (int it = 0; it < cfg.iterations && it < needed; ++it) {
    const Sample s = draw_sample(rng, n);
    if (!well_conditioned(a[s[0]], a[s[1]], a[s[2]], cfg) || !well_conditioned(b[s[0]], b[s[1]], b[s[2]], cfg))
      continue;
    if (!distances_agree(s, a, b, tol)) continue;
    const Eigen::Isometry3d T = fit_rigid(a, b, s);
    Consensus c = evaluate(T, a, b, tol);
    if (c.score >= best.score) continue;
    best = std::move(c);
    best_T = T;
    if (cfg.confidence > 0) needed = samples_needed(static_cast<double>(best.inliers) / static_cast<double>(n), cfg.confidence);
  }
  if (best.inliers < 3) return result;

  refine(best_T, best, a, b, tol, cfg.refine_iterations, tolerance && cfg.weight_refit_by_tolerance);
  result.T_ab = best_T;
  result.inlier = std::move(best.inlier);
  result.inliers = best.inliers;
  result.ok = result.inliers >= min_inliers;
  return result;
}

}  // namespace varslam::optim
