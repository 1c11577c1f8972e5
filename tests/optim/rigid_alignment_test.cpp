#include <gtest/gtest.h>

#include <iostream>
#include <random>
#include <stdexcept>

#include "optim/rigid_alignment.hpp"

namespace varslam::optim {
namespace {

Eigen::Isometry3d known_transform() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1.0, 0.5).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(1.5, -0.4, 2.0);
  return T;
}

double rotation_error(const Eigen::Isometry3d& A, const Eigen::Isometry3d& B) {
  return Eigen::AngleAxisd(A.rotation().transpose() * B.rotation()).angle();
}

/// A point in front of an RGB-D camera: x, y in [-2, 2] m, depth z in [1, 5] m.
Eigen::Vector3d random_scene_point(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> xy(-2.0, 2.0), z(1.0, 5.0);
  return {xy(rng), xy(rng), z(rng)};
}

Eigen::Vector3d random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  return Eigen::Vector3d(n01(rng), n01(rng), n01(rng)).normalized();
}

struct Correspondences {
  std::vector<Eigen::Vector3d> a, b;
  std::vector<bool> is_outlier;
};

/// a_i = T b_i + noise (noise_sigma per axis) for inliers; every other correspondence's a is a random point.
Correspondences make_correspondences(int n, double outlier_fraction, double noise_sigma, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_sigma);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const Eigen::Isometry3d T = known_transform();
  Correspondences c;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d b = random_scene_point(rng);
    const bool outlier = u01(rng) < outlier_fraction;
    c.b.push_back(b);
    c.a.push_back(outlier ? T * random_scene_point(rng)
                          : Eigen::Vector3d(T * b + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))));
    c.is_outlier.push_back(outlier);
  }
  return c;
}

TEST(RigidRansac, RecoversTransformWithHalfGrossOutliersAndFlagsThem) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const Correspondences c = make_correspondences(300, 0.5, 0.001, seed);
    const RigidRansacResult r = estimate_rigid_ransac(c.a, c.b, RigidRansacConfig{});
    ASSERT_TRUE(r.ok) << "seed " << seed;
    EXPECT_LT(rotation_error(r.T_ab, known_transform()), 1e-3) << "seed " << seed;
    EXPECT_LT((r.T_ab.translation() - known_transform().translation()).norm(), 1e-3) << "seed " << seed;
    ASSERT_EQ(r.inlier.size(), c.a.size());
    int true_inliers = 0;
    for (std::size_t i = 0; i < c.a.size(); ++i) {
      EXPECT_EQ(r.inlier[i], !c.is_outlier[i]) << "seed " << seed << " correspondence " << i;
      true_inliers += !c.is_outlier[i];
    }
    EXPECT_EQ(r.inliers, true_inliers);
  }
}

TEST(RigidRansac, TooFewCorrespondencesFail) {
  const Correspondences c = make_correspondences(10, 0.0, 0.0, 4);
  RigidRansacConfig cfg;
  cfg.min_inliers = 20;
  EXPECT_FALSE(estimate_rigid_ransac(c.a, c.b, cfg).ok);

  const Correspondences two = make_correspondences(2, 0.0, 0.0, 4);
  cfg.min_inliers = 0;  // even without a minimum, 3 points are needed for a rigid fit
  const RigidRansacResult r = estimate_rigid_ransac(two.a, two.b, cfg);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.inlier.size(), 2u);

  const std::vector<Eigen::Vector3d> none;
  EXPECT_FALSE(estimate_rigid_ransac(none, none, cfg).ok);
}

TEST(RigidRansac, UnrelatedPointSetsFail) {
  const Correspondences c = make_correspondences(200, 1.0, 0.0, 5);
  RigidRansacConfig cfg;
  cfg.iterations = 1000;
  const RigidRansacResult r = estimate_rigid_ransac(c.a, c.b, cfg);
  EXPECT_FALSE(r.ok);
  EXPECT_LT(r.inliers, cfg.min_inliers);
}

TEST(RigidRansac, CollinearPointsAreDegenerate) {
  // Any rotation about the line fits them: no sample may be accepted.
  std::vector<Eigen::Vector3d> a, b;
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d p = Eigen::Vector3d(0.1, 0.2, 1.0) + 0.05 * i * Eigen::Vector3d(1, 1, 1).normalized();
    b.push_back(p);
    a.push_back(known_transform() * p);
  }
  const RigidRansacResult r = estimate_rigid_ransac(a, b, RigidRansacConfig{});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.inliers, 0);
}

TEST(RigidRansac, SameSeedSameResult) {
  const Correspondences c = make_correspondences(200, 0.5, 0.005, 6);
  RigidRansacConfig cfg;
  cfg.refine_iterations = 0;  // keep the sampled model, so that the seed visibly matters
  cfg.confidence = 0;
  cfg.seed = 17;
  const RigidRansacResult r1 = estimate_rigid_ransac(c.a, c.b, cfg);
  const RigidRansacResult r2 = estimate_rigid_ransac(c.a, c.b, cfg);
  ASSERT_TRUE(r1.ok);
  EXPECT_EQ(r1.T_ab.matrix(), r2.T_ab.matrix());
  EXPECT_EQ(r1.inlier, r2.inlier);
  cfg.seed = 18;
  const RigidRansacResult r3 = estimate_rigid_ransac(c.a, c.b, cfg);
  EXPECT_NE(r1.T_ab.matrix(), r3.T_ab.matrix());  // the seed is really used
}

TEST(RigidRansac, PerCorrespondenceToleranceIsHonoured) {
  // Depth noise grows with z^2: inliers are displaced by 0.8 of their tolerance 0.01 + 0.003 z^2 (up to 6.8 cm
  // at 5 m), and near points (z < 2 m, tolerance < 2.2 cm) of every 5th correspondence by 3 cm (outliers there).
  std::mt19937_64 rng(8);
  const Eigen::Isometry3d T = known_transform();
  std::vector<Eigen::Vector3d> a, b;
  std::vector<double> tolerance;
  std::vector<bool> displaced_near;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d p = random_scene_point(rng);
    const double tol = 0.01 + 0.003 * p.z() * p.z();
    const bool near_outlier = p.z() < 2.0 && i % 5 == 0;
    b.push_back(p);
    a.push_back(T * p + (near_outlier ? 0.03 : 0.8 * tol) * random_direction(rng));
    tolerance.push_back(tol);
    displaced_near.push_back(near_outlier);
  }
  RigidRansacConfig cfg;
  cfg.inlier_threshold = 0.05;
  const RigidRansacResult with_tol = estimate_rigid_ransac(a, b, cfg, &tolerance);
  ASSERT_TRUE(with_tol.ok);
  int far_noisy = 0, far_noisy_flagged_by_global = 0;
  const RigidRansacResult global = estimate_rigid_ransac(a, b, cfg);
  ASSERT_TRUE(global.ok);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(with_tol.inlier[i], !displaced_near[i]) << "correspondence " << i;
    if (0.8 * tolerance[i] > 0.06) {
      ++far_noisy;
      far_noisy_flagged_by_global += !global.inlier[i];
    }
    if (displaced_near[i]) {
      EXPECT_TRUE(global.inlier[i]) << "3 cm is within the global 5 cm";
    }
  }
  ASSERT_GT(far_noisy, 5);
  EXPECT_EQ(far_noisy_flagged_by_global, far_noisy);  // the global threshold rejects the far noisy inliers
}

/// Correspondences whose noise grows with depth: a_i = T b_i + N(0, (tol_i / 3)^2) per axis, tol_i = 0.01 + 0.003 z^2;
/// a third are gross outliers.
Correspondences make_depth_noisy(int n, unsigned seed, std::vector<double>& tolerance) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const Eigen::Isometry3d T = known_transform();
  Correspondences c;
  tolerance.clear();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p = random_scene_point(rng);
    const double tol = 0.01 + 0.003 * p.z() * p.z();
    const bool outlier = i % 3 == 0;
    c.b.push_back(p);
    c.a.push_back(outlier ? Eigen::Vector3d(T * random_scene_point(rng))
                          : Eigen::Vector3d(T * p + (tol / 3.0) * Eigen::Vector3d(n01(rng), n01(rng), n01(rng))));
    c.is_outlier.push_back(outlier);
    tolerance.push_back(tol);
  }
  return c;
}

TEST(RigidRansac, ToleranceWeightedRefitIsMoreAccurate) {
  double err_weighted = 0, err_plain = 0;
  constexpr int kRuns = 30;
  for (unsigned seed = 1; seed <= kRuns; ++seed) {
    std::vector<double> tolerance;
    const Correspondences c = make_depth_noisy(150, seed, tolerance);
    RigidRansacConfig cfg;
    const RigidRansacResult weighted = estimate_rigid_ransac(c.a, c.b, cfg, &tolerance);
    cfg.weight_refit_by_tolerance = false;
    const RigidRansacResult plain = estimate_rigid_ransac(c.a, c.b, cfg, &tolerance);
    ASSERT_TRUE(weighted.ok && plain.ok);
    // Error at the scene's centre (0, 0, 3): rotation and translation errors together.
    const Eigen::Vector3d centre(0, 0, 3);
    err_weighted += (weighted.T_ab * centre - known_transform() * centre).norm();
    err_plain += (plain.T_ab * centre - known_transform() * centre).norm();
  }
  std::cout << "[ rigid ransac ] mean error at 3 m: weighted " << err_weighted / kRuns << " m, plain " << err_plain / kRuns
            << " m\n";
  EXPECT_LT(err_weighted, 0.8 * err_plain);
}

TEST(RigidRansac, RejectsMismatchedSizes) {
  const Correspondences c = make_correspondences(30, 0.0, 0.0, 9);
  std::vector<Eigen::Vector3d> shorter(c.b.begin(), c.b.end() - 1);
  EXPECT_THROW(estimate_rigid_ransac(c.a, shorter, RigidRansacConfig{}), std::invalid_argument);
  const std::vector<double> tol(5, 0.01);
  EXPECT_THROW(estimate_rigid_ransac(c.a, c.b, RigidRansacConfig{}, &tol), std::invalid_argument);
}

}  // namespace
}  // namespace varslam::optim
