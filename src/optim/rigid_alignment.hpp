#pragma once
// Rigid 3-D/3-D alignment with RANSAC (RGB-D relocalisation / loop verification). Pure math: Eigen + std only.
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

namespace varslam::optim {

struct RigidRansacConfig {
  int iterations = 200;            // maximum number of minimal samples drawn
  double inlier_threshold = 0.05;  // metres: |a_i - T b_i| below it is an inlier (unless per-point tolerances)
  int min_inliers = 20;            // fewer final inliers: ok = false
  std::uint64_t seed = 1;          // std::mt19937_64 seed: same seed, same result
  // Stop sampling early once a model with this inlier ratio would have been drawn with `confidence`
  // (standard RANSAC bound for samples of 3); 0 disables early stopping.
  double confidence = 0.999;
  // Degenerate samples are skipped: every side of the sample triangle (in both point sets) must be at least
  // min_sample_side metres, and the triangle's smallest height at least min_sample_height_ratio times its
  // longest side (rejects near-collinear triples, whose rotation about the line is unobservable).
  double min_sample_side = 0.02;
  double min_sample_height_ratio = 0.1;
  int refine_iterations = 10;  // refits on all inliers (re-counted after each) while the inlier set changes
  // With per-correspondence tolerances, weigh each inlier by 1 / tolerance^2 in the refit (maximum likelihood
  // when the tolerance scales the noise), so the precise near points are not pulled off by the far ones.
  bool weight_refit_by_tolerance = true;
};

struct RigidRansacResult {
  bool ok = false;
  Eigen::Isometry3d T_ab = Eigen::Isometry3d::Identity();  // a_i ~ T_ab * b_i
  std::vector<bool> inlier;                                // per correspondence, for T_ab
  int inliers = 0;
};

/// Finds T_ab with a_i ~ T_ab * b_i from correspondences with gross outliers: minimal samples of 3, each fit
/// by Eigen::umeyama (no scaling), models scored by a truncated quadratic (MSAC), the best one refit on its
/// inliers. `tolerance` (optional, metres per correspondence, e.g. 0.01 + 0.003 z^2 for RGB-D depth noise)
/// replaces the global inlier_threshold: correspondence i is an inlier when |a_i - T b_i| < tolerance[i].
/// ok = false when there are fewer than max(3, min_inliers) correspondences or final inliers.
/// Throws std::invalid_argument when a, b (and tolerance) differ in size.
RigidRansacResult estimate_rigid_ransac(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                                        const RigidRansacConfig& cfg, const std::vector<double>* tolerance = nullptr);

}  // namespace varslam::optim
