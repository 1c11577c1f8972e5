#include "optim/synthetic_problems.hpp"

#include <cmath>
#include <random>

#include "core/geometry.hpp"

namespace varslam::optim {
namespace {

constexpr double kScaleFactor = 1.2;  // ORB pyramid scale
constexpr int kLevels = 8;

Eigen::Isometry3d perturbed(const Eigen::Isometry3d& T, double rot, double trans, std::mt19937& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  Eigen::Matrix<double, 6, 1> xi;
  const Eigen::Vector3d w(n01(rng), n01(rng), n01(rng));
  const Eigen::Vector3d v(n01(rng), n01(rng), n01(rng));
  xi << rot * w.normalized(), trans * v.normalized();
  return se3_left_update(T, xi);
}

/// Noisy observation of p_c at a random pyramid level; false when not visible.
bool observe(const PinholeCamera& cam, const Eigen::Vector3d& p_c, bool stereo, double pixel_noise, std::mt19937& rng,
             Observation* out) {
  if (p_c.z() <= 0.1) return false;
  const Eigen::Vector2d uv = cam.project(p_c);
  if (!cam.in_image(uv.x(), uv.y())) return false;
  const int level = std::uniform_int_distribution<int>(0, kLevels - 1)(rng);
  const double scale = std::pow(kScaleFactor, level);
  std::normal_distribution<double> noise(0.0, pixel_noise * scale);
  out->uv = uv + Eigen::Vector2d(noise(rng), noise(rng));
  out->inv_sigma2 = 1.0 / (scale * scale);
  out->u_right = stereo ? uv.x() - cam.bf / p_c.z() + noise(rng) : -1.0;
  if (stereo && out->u_right < 0) out->u_right = 0.0;  // keep it a stereo observation
  return true;
}

Eigen::Vector3d random_point(std::mt19937& rng) {
  std::uniform_real_distribution<double> ux(-2.5, 2.5), uy(-1.8, 1.8), uz(3.0, 8.0);
  return {ux(rng), uy(rng), uz(rng)};
}

}  // namespace

SyntheticPose make_synthetic_pose(const PinholeCamera& cam, const SyntheticPoseOptions& opt) {
  std::mt19937 rng(opt.seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  SyntheticPose s;
  s.T_true = Eigen::Isometry3d::Identity();
  s.T_true.linear() = so3_exp(Eigen::Vector3d(0.05, -0.1, 0.02));
  s.T_true.translation() << 0.3, -0.1, 0.2;
  s.T_init = perturbed(s.T_true, opt.rotation_error, opt.translation_error, rng);
  const Eigen::Isometry3d T_wc = s.T_true.inverse();
  while (static_cast<int>(s.obs.size()) < opt.observations) {
    const Eigen::Vector3d p_c = random_point(rng);
    Observation o;
    if (!observe(cam, p_c, u01(rng) < opt.stereo_fraction, opt.pixel_noise, rng, &o)) continue;
    const bool outlier = u01(rng) < opt.outlier_fraction;
    if (outlier) {
      // A wrong match: some other pixel (and depth) in the image.
      o.uv = Eigen::Vector2d(u01(rng) * cam.width, u01(rng) * cam.height);
      if (o.stereo()) o.u_right = std::max(0.0, o.uv.x() - cam.bf / (1.0 + 8.0 * u01(rng)));
    }
    s.points_w.push_back(T_wc * p_c);
    s.obs.push_back(o);
    s.is_outlier.push_back(outlier);
  }
  return s;
}

SyntheticBa make_synthetic_ba(const PinholeCamera& cam, const SyntheticBaOptions& opt) {
  std::mt19937 rng(opt.seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> n01(0.0, 1.0);
  SyntheticBa s;
  BaProblem& truth = s.truth;
  // Keyframes on an arc, 15 cm apart, turning slightly, all looking into the point volume.
  for (int k = 0; k < opt.keyframes; ++k) {
    const double x = 0.15 * (k - 0.5 * (opt.keyframes - 1));
    Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
    T_wc.linear() = so3_exp(Eigen::Vector3d(0.02 * std::sin(k), -0.03 * x, 0.01 * k));
    T_wc.translation() << x, 0.05 * std::sin(0.7 * k), 0.03 * k;
    truth.keyframes.push_back({T_wc.inverse(), k < opt.fixed_keyframes});
  }
  while (static_cast<int>(truth.points.size()) < opt.points) {
    const Eigen::Vector3d p_w = random_point(rng);
    std::vector<BaObservation> seen;
    for (int k = 0; k < opt.keyframes; ++k) {
      if (u01(rng) >= opt.observe_probability) continue;
      BaObservation bo{k, static_cast<int>(truth.points.size()), {}};
      if (observe(cam, truth.keyframes[k].T_cw * p_w, u01(rng) < opt.stereo_fraction, opt.pixel_noise, rng, &bo.obs))
        seen.push_back(bo);
    }
    if (seen.size() < 2) continue;  // a point seen once constrains nothing
    truth.points.push_back(p_w);
    truth.observations.insert(truth.observations.end(), seen.begin(), seen.end());
  }
  s.initial = truth;
  for (BaKeyframe& kf : s.initial.keyframes)
    if (!kf.fixed) kf.T_cw = perturbed(kf.T_cw, opt.rotation_error, opt.translation_error, rng);
  for (Eigen::Vector3d& p : s.initial.points) p += opt.point_error * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
  return s;
}

double point_rmse(const BaProblem& a, const BaProblem& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.points.size(); ++i) sum += (a.points[i] - b.points[i]).squaredNorm();
  return a.points.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(a.points.size()));
}

double mean_translation_error(const BaProblem& a, const BaProblem& b) {
  double sum = 0;
  for (std::size_t k = 0; k < a.keyframes.size(); ++k)
    sum += (a.keyframes[k].T_cw.inverse().translation() - b.keyframes[k].T_cw.inverse().translation()).norm();
  return a.keyframes.empty() ? 0.0 : sum / static_cast<double>(a.keyframes.size());
}

double mean_rotation_error(const BaProblem& a, const BaProblem& b) {
  double sum = 0;
  for (std::size_t k = 0; k < a.keyframes.size(); ++k)
    sum += rotation_angle(a.keyframes[k].T_cw.rotation(), b.keyframes[k].T_cw.rotation());
  return a.keyframes.empty() ? 0.0 : sum / static_cast<double>(a.keyframes.size());
}

}  // namespace varslam::optim
