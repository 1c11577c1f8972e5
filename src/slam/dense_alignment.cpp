#include "slam/dense_alignment.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/geometry.hpp"

namespace varslam::slam {

namespace {

bool has_depth(float d) { return std::isfinite(d) && d > 0; }

std::uint16_t to_mm(double z_m) { return static_cast<std::uint16_t>(std::min(1000.0 * z_m + 0.5, 65535.0)); }

}  // namespace

cv::Mat depth_mm_every(const cv::Mat& depth_m, int step) {
  cv::Mat mm;
  if (depth_m.empty() || depth_m.type() != CV_32FC1 || step < 1) return mm;
  mm.create((depth_m.rows + step - 1) / step, (depth_m.cols + step - 1) / step, CV_16UC1);
  for (int r = 0; r < mm.rows; ++r) {
    const float* in = depth_m.ptr<float>(r * step);
    auto* out = mm.ptr<std::uint16_t>(r);
    for (int c = 0; c < mm.cols; ++c) {
      const float d = in[c * step];
      out[c] = has_depth(d) ? to_mm(d) : 0;
    }
  }
  return mm;
}

namespace {

// Mean depth of the pixels within `radius` of (x, y) that have depth, are not masked and lie within `tolerance` of
// `reference`; 0 for none.
double gated_mean(const cv::Mat& depth_m, const cv::Mat& mask, int x, int y, int radius, double reference,
                  double tolerance) {
  double sum = 0;
  int n = 0;
  for (int yy = std::max(0, y - radius); yy <= std::min(depth_m.rows - 1, y + radius); ++yy) {
    const float* row = depth_m.ptr<float>(yy);
    const std::uint8_t* masked = mask.empty() ? nullptr : mask.ptr<std::uint8_t>(yy);
    for (int xx = std::max(0, x - radius); xx <= std::min(depth_m.cols - 1, x + radius); ++xx)
      if (has_depth(row[xx]) && (!masked || !masked[xx]) &&
          std::abs(row[xx] - reference) <= tolerance) {
        sum += row[xx];
        ++n;
      }
  }
  return n > 0 ? sum / n : 0.0;
}

}  // namespace

DepthSample DepthSample::of(const cv::Mat& depth_m, const cv::Mat& mover_mask) {
  DepthSample s;
  if (depth_m.empty() || depth_m.type() != CV_32FC1) return s;
  if (!mover_mask.empty() && (mover_mask.size() != depth_m.size() || mover_mask.type() != CV_8UC1))
    throw std::invalid_argument("DepthSample::of: the mover mask must be CV_8UC1 of the depth's size");
  s.depth_mm.create((depth_m.rows + kStep - 1) / kStep, (depth_m.cols + kStep - 1) / kStep, CV_16UC1);
  for (int r = 0; r < s.depth_mm.rows; ++r)
    for (int c = 0; c < s.depth_mm.cols; ++c) {
      const int y = r * kStep, x = c * kStep;
      const float centre = depth_m.at<float>(y, x);
      auto& out = s.depth_mm.at<std::uint16_t>(r, c);
      out = 0;
      if (!has_depth(centre) || (!mover_mask.empty() && mover_mask.at<std::uint8_t>(y, x)))
        continue;
      const double tolerance = 0.02 * centre + 0.005;
      // The centre pixel is as noisy as any other: the second pass gates around the first pass's mean instead.
      double z = gated_mean(depth_m, mover_mask, x, y, kWindow, centre, tolerance);
      z = gated_mean(depth_m, mover_mask, x, y, kWindow, z, tolerance);
      if (z > 0) out = to_mm(z);
    }
  return s;
}

namespace {

// The pixel (u, v) of the sample's grid back-projected; zero without depth.
cv::Vec3f point_at(const DepthSample& s, const PinholeCamera& cam, int r, int c) {
  const double z = 0.001 * s.depth_mm.at<std::uint16_t>(r, c);
  if (z <= 0) return {0, 0, 0};
  const Eigen::Vector3d p = cam.unproject(c, r, z);
  return {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
}

bool smooth_neighbour(float z, float n) { return n > 0 && std::abs(n - z) < 0.03f * z + 0.01f; }

}  // namespace

Surface surface_of(const DepthSample& sample, const PinholeCamera& full_camera) {
  Surface s;
  s.camera = full_camera;
  const double k = DepthSample::kStep;
  s.camera.fx /= k;
  s.camera.fy /= k;
  // Sample pixel c sits at full-resolution pixel k * c.
  s.camera.cx /= k;
  s.camera.cy /= k;
  s.camera.width = sample.depth_mm.cols;
  s.camera.height = sample.depth_mm.rows;
  s.points.create(sample.depth_mm.size(), CV_32FC3);
  s.normals = cv::Mat::zeros(sample.depth_mm.size(), CV_32FC3);
  for (int r = 0; r < sample.depth_mm.rows; ++r)
    for (int c = 0; c < sample.depth_mm.cols; ++c) s.points.at<cv::Vec3f>(r, c) = point_at(sample, s.camera, r, c);
  for (int r = 1; r + 1 < sample.depth_mm.rows; ++r)
    for (int c = 1; c + 1 < sample.depth_mm.cols; ++c) {
      const cv::Vec3f p = s.points.at<cv::Vec3f>(r, c);
      const cv::Vec3f l = s.points.at<cv::Vec3f>(r, c - 1), rt = s.points.at<cv::Vec3f>(r, c + 1);
      const cv::Vec3f up = s.points.at<cv::Vec3f>(r - 1, c), dn = s.points.at<cv::Vec3f>(r + 1, c);
      if (p[2] <= 0 || !smooth_neighbour(p[2], l[2]) || !smooth_neighbour(p[2], rt[2]) ||
          !smooth_neighbour(p[2], up[2]) || !smooth_neighbour(p[2], dn[2]))
        continue;
      cv::Vec3f n = (rt - l).cross(dn - up);
      const float len = static_cast<float>(cv::norm(n));
      if (len <= 0) continue;
      n /= len;
      if (n.dot(p) > 0) n = -n;  // facing the camera
      s.normals.at<cv::Vec3f>(r, c) = n;
    }
  return s;
}

std::optional<DenseAlignment> align_surfaces(const Surface& target, const Surface& source,
                                             const Eigen::Isometry3d& T_target_source_guess,
                                             const DenseAlignConfig& cfg) {
  std::vector<Eigen::Vector3d> src;
  for (int r = 0; r < source.points.rows; ++r)
    for (int c = 0; c < source.points.cols; ++c) {
      const cv::Vec3f p = source.points.at<cv::Vec3f>(r, c);
      if (p[2] > 0) src.emplace_back(p[0], p[1], p[2]);
    }
  if (src.empty()) return std::nullopt;
  const PinholeCamera& cam = target.camera;
  Eigen::Isometry3d T = T_target_source_guess;
  DenseAlignment out;
  bool final_gate = false;
  for (int it = 0; it < cfg.iterations; ++it) {
    final_gate = final_gate || it >= cfg.first_gate_iterations;
    const double gate = final_gate ? cfg.final_gate_m : cfg.first_gate_m;
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    int pairs = 0;
    double sum_sq = 0;
    for (const Eigen::Vector3d& p : src) {
      const Eigen::Vector3d q = T * p;
      if (q.z() <= 0.1) continue;
      const Eigen::Vector2d uv = cam.project(q);
      const int c = static_cast<int>(std::lround(uv.x())), r = static_cast<int>(std::lround(uv.y()));
      if (c < 0 || r < 0 || c >= target.points.cols || r >= target.points.rows) continue;
      const cv::Vec3f nv = target.normals.at<cv::Vec3f>(r, c);
      if (nv[0] == 0 && nv[1] == 0 && nv[2] == 0) continue;
      const cv::Vec3f tv = target.points.at<cv::Vec3f>(r, c);
      const Eigen::Vector3d n(nv[0], nv[1], nv[2]), t(tv[0], tv[1], tv[2]);
      const double res = n.dot(q - t);
      if (std::abs(res) > gate) continue;
      Eigen::Matrix<double, 6, 1> J;
      J << q.cross(n), n;  // d res / d (rotation, translation) of a left increment
      const double w = std::abs(res) <= cfg.huber_m ? 1.0 : cfg.huber_m / std::abs(res);
      A += w * J * J.transpose();
      b += w * res * J;
      ++pairs;
      sum_sq += res * res;
    }
    if (pairs < cfg.min_pairs) return std::nullopt;
    out.overlap = static_cast<double>(pairs) / static_cast<double>(src.size());
    out.rms_m = std::sqrt(sum_sq / pairs);
    const Eigen::Matrix<double, 6, 1> dx = -(A + 1e-9 * Eigen::Matrix<double, 6, 6>::Identity()).ldlt().solve(b);
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step.linear() = so3_exp(dx.head<3>());
    step.translation() = dx.tail<3>();
    T = step * T;
    if (dx.norm() < cfg.settled_step) {
      if (final_gate) break;
      final_gate = true;  // settled under the wide gate: go on to the narrow one at once
    }
  }
  out.T_target_source = T;
  return out;
}

}  // namespace varslam::slam
