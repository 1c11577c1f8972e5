#include "synth/sensor.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace varslam::synth {

namespace {

// Unit-variance Gaussian noise smoothed over sigma pixels: white noise blurred, rescaled by the blur's gain
// (a 2-D Gaussian of sigma s keeps 1 / (4 pi s^2) of white noise's variance).
cv::Mat1f smooth_noise(int rows, int cols, double sigma, SplitMix64& rng, const GaussianTable& gauss) {
  cv::Mat1f n(rows, cols);
  for (int v = 0; v < rows; ++v) {
    float* row = n.ptr<float>(v);
    for (int u = 0; u < cols; ++u) row[u] = gauss.draw(rng);
  }
  cv::GaussianBlur(n, n, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT);
  n *= static_cast<float>(std::sqrt(4.0 * M_PI) * sigma);
  return n;
}

bool dark(const cv::Vec3f& bgr) { return 0.114f * bgr[0] + 0.587f * bgr[1] + 0.299f * bgr[2] < 0.1f; }

}  // namespace

cv::Mat1w sense_depth(const cv::Mat1f& depth_m, const DepthSensorParams& p, SplitMix64& rng, const GaussianTable& gauss,
                      const cv::Mat3f* color) {
  const int H = depth_m.rows, W = depth_m.cols;
  cv::Mat1w out(H, W);
  cv::Mat1f field;
  if (p.noise && p.noise_blur_px > 0) {
    SplitMix64 field_rng(rng.next());
    field = smooth_noise(H, W, p.noise_blur_px, field_rng, gauss);
  }
  SplitMix64 dark_rng(p.dark_dropout > 0 ? rng.next() : 0);
  for (int v = 0; v < H; ++v) {
    const float* d = depth_m.ptr<float>(v);
    const float* up = depth_m.ptr<float>(std::max(0, v - 1));
    const float* dn = depth_m.ptr<float>(std::min(H - 1, v + 1));
    auto* o = out.ptr<std::uint16_t>(v);
    for (int u = 0; u < W; ++u) {
      // Two draws per pixel whatever it shows, so a pixel's noise does not depend on the content elsewhere in the
      // image: scenes that differ only by a mover get identical noise away from the mover.
      const double hole_draw = p.edge_holes ? rng.uniform() : 1.0;
      const float noise_draw = p.noise ? (field.empty() ? gauss.draw(rng) : field(v, u)) : 0.0f;
      double z = d[u];
      if (z <= 0 || (p.max_range_m > 0 && z > p.max_range_m)) {
        o[u] = 0;
        continue;
      }
      if (p.dark_dropout > 0 && color && dark((*color)(v, u)) && dark_rng.uniform() < p.dark_dropout) {
        o[u] = 0;
        continue;
      }
      if (p.edge_holes) {
        // Structured-light sensors lose depth where the surface jumps (shadowed pattern): drop pixels next to
        // a discontinuity larger than a few percent of the depth, the farther side more often.
        const float l = d[std::max(0, u - 1)], r = d[std::min(W - 1, u + 1)];
        const float jump = std::max({std::abs(l - d[u]), std::abs(r - d[u]), std::abs(up[u] - d[u]), std::abs(dn[u] - d[u])});
        const bool far_side = l < d[u] - 0.04f * d[u] || r < d[u] - 0.04f * d[u] || up[u] < d[u] - 0.04f * d[u] ||
                              dn[u] < d[u] - 0.04f * d[u];
        if (jump > 0.04f * d[u] && hole_draw < (far_side ? 0.9 : 0.5)) {
          o[u] = 0;
          continue;
        }
      }
      if (p.noise) z += kinect_depth_sigma(z) * noise_draw;
      z *= p.scale;
      // A structured-light sensor measures disparity: depth comes in steps of 1/z, about step * z^2 apart.
      if (p.inverse_depth_step > 0 && z > 0) z = 1.0 / (std::max(1.0, std::round(1.0 / (z * p.inverse_depth_step))) * p.inverse_depth_step);
      const double raw = std::round(z * p.depth_factor);
      o[u] = static_cast<std::uint16_t>(std::clamp(raw, 0.0, 65535.0));
    }
  }
  // A few random blobs of missing depth (specular or absorbing spots).
  for (int i = 0; i < p.random_holes; ++i) {
    const cv::Point c(static_cast<int>(rng.uniform() * W), static_cast<int>(rng.uniform() * H));
    const cv::Size axes(2 + static_cast<int>(rng.uniform() * 8), 2 + static_cast<int>(rng.uniform() * 6));
    cv::ellipse(out, c, axes, rng.uniform() * 180, 0, 360, cv::Scalar(0), -1);
  }
  return out;
}

void motion_blur(cv::Mat3f& img, double dx, double dy) {
  const double len = std::hypot(dx, dy);
  if (len < 1.0) return;
  const int k = std::min(31, static_cast<int>(std::ceil(len)) | 1);
  cv::Mat1f kernel = cv::Mat1f::zeros(k, k);
  const int steps = 4 * k;
  for (int i = 0; i < steps; ++i) {
    const double s = (i + 0.5) / steps - 0.5;
    const double x = (k - 1) / 2.0 + s * dx, y = (k - 1) / 2.0 + s * dy;
    const int xi = std::clamp(static_cast<int>(std::lround(x)), 0, k - 1);
    const int yi = std::clamp(static_cast<int>(std::lround(y)), 0, k - 1);
    kernel(yi, xi) += 1.0f;
  }
  kernel /= static_cast<float>(cv::sum(kernel)[0]);
  cv::filter2D(img, img, -1, kernel, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
}

cv::Mat3b sense_color(const cv::Mat3f& img, double gain, double noise_sigma, SplitMix64& rng, const GaussianTable& gauss) {
  cv::Mat3b out(img.size());
  const float g = static_cast<float>(gain * 255.0), s = static_cast<float>(noise_sigma);
  for (int v = 0; v < img.rows; ++v) {
    const auto* in = img.ptr<cv::Vec3f>(v);
    auto* o = out.ptr<cv::Vec3b>(v);
    for (int u = 0; u < img.cols; ++u) {
      // Luminance-correlated noise plus a smaller per-channel part, as on a Bayer sensor after demosaicing.
      const float common = s * 0.8f * gauss.draw(rng);
      for (int c = 0; c < 3; ++c)
        o[u][c] = cv::saturate_cast<uchar>(in[u][c] * g + common + s * 0.6f * gauss.draw(rng));
    }
  }
  return out;
}

}  // namespace varslam::synth
