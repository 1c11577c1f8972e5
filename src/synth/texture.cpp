#include "synth/texture.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "synth/fast_rng.hpp"

namespace varslam::synth {

namespace {
bool is_pow2(int v) { return v > 0 && (v & (v - 1)) == 0; }

// log2 to about 0.01: exponent from frexp plus a quadratic for the mantissa (mip selection needs no more).
double fast_log2(double x) {
  int e;
  const double m = std::frexp(x, &e);  // x = m 2^e, m in [0.5, 1)
  const double y = 2.0 * m - 1.0;      // [0, 1)
  return (e - 1) + y * (1.3465 - 0.3465 * y);
}
}  // namespace

Texture::Texture(const cv::Mat& bgr) {
  CV_Assert(bgr.type() == CV_8UC3 && is_pow2(bgr.cols) && is_pow2(bgr.rows));
  levels_.push_back(bgr.clone());
  // Box-filtered pyramid down to 1 pixel in the smaller dimension (power-of-two keeps the wrap exact).
  while (levels_.back().cols > 1 && levels_.back().rows > 1) {
    cv::Mat next;
    cv::resize(levels_.back(), next, cv::Size(levels_.back().cols / 2, levels_.back().rows / 2), 0, 0,
               cv::INTER_AREA);
    levels_.push_back(next);
  }
}

cv::Vec3f Texture::bilinear(int level, double u, double v) const {
  const cv::Mat& m = levels_[static_cast<std::size_t>(level)];
  const float scale = 1.0f / static_cast<float>(1 << level);
  const float x = static_cast<float>(u) * scale - 0.5f, y = static_cast<float>(v) * scale - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float ax = x - fx, ay = y - fy;
  const int wm = m.cols - 1, hm = m.rows - 1;  // sizes are powers of two: & wraps, also for negative values
  const int x0 = static_cast<int>(fx) & wm, y0 = static_cast<int>(fy) & hm;
  const int x1 = (x0 + 1) & wm, y1 = (y0 + 1) & hm;
  const auto* r0 = m.ptr<cv::Vec3b>(y0);
  const auto* r1 = m.ptr<cv::Vec3b>(y1);
  const float w00 = (1 - ax) * (1 - ay) * (1.0f / 255.0f), w10 = ax * (1 - ay) * (1.0f / 255.0f);
  const float w01 = (1 - ax) * ay * (1.0f / 255.0f), w11 = ax * ay * (1.0f / 255.0f);
  cv::Vec3f out;
  for (int c = 0; c < 3; ++c) out[c] = w00 * r0[x0][c] + w10 * r0[x1][c] + w01 * r1[x0][c] + w11 * r1[x1][c];
  return out;
}

cv::Vec3f Texture::sample(double u, double v, double footprint) const {
  const int max_level = static_cast<int>(levels_.size()) - 1;
  const double lod = footprint > 1.0 ? fast_log2(footprint) : 0.0;
  if (lod <= 0.0) return bilinear(0, u, v);
  if (lod >= max_level) return bilinear(max_level, u, v);
  const int l0 = static_cast<int>(lod);
  const float f = static_cast<float>(lod - l0);
  const cv::Vec3f a = bilinear(l0, u, v);
  if (f < 0.02f) return a;
  return a + f * (bilinear(l0 + 1, u, v) - a);
}

namespace texgen {

namespace {
float lattice(std::uint64_t seed, int x, int y) {
  const std::uint64_t h = mix_seed(seed, (static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32) ^
                                             static_cast<std::uint32_t>(y));
  return static_cast<float>(h >> 40) * (1.0f / 16777216.0f);
}
cv::Vec3b scale_color(cv::Vec3b c, float k) {
  return {cv::saturate_cast<uchar>(c[0] * k), cv::saturate_cast<uchar>(c[1] * k), cv::saturate_cast<uchar>(c[2] * k)};
}
cv::Mat colorize(const cv::Mat1f& f, cv::Vec3b base, float contrast) {
  cv::Mat out(f.size(), CV_8UC3);
  for (int y = 0; y < f.rows; ++y)
    for (int x = 0; x < f.cols; ++x) out.at<cv::Vec3b>(y, x) = scale_color(base, 1.0f + contrast * (f(y, x) - 0.5f));
  return out;
}
}  // namespace

cv::Mat1f fbm(int w, int h, std::uint64_t seed, int cells, int octaves, double persistence) {
  cv::Mat1f out(h, w, 0.0f);
  double amp = 1.0, total = 0.0;
  for (int o = 0; o < octaves; ++o) {
    const int period = cells << o;  // lattice period in cells: the image stays tileable
    const int period_y = std::max(1, period * h / w);
    const double cell_w = static_cast<double>(w) / period, cell_h = static_cast<double>(h) / period_y;
    const std::uint64_t s = mix_seed(seed, static_cast<std::uint64_t>(o));
    // Lattice values once per octave (hashing per pixel would dominate scene setup).
    std::vector<float> grid(static_cast<std::size_t>(period * period_y));
    for (int gy = 0; gy < period_y; ++gy)
      for (int gx = 0; gx < period; ++gx) grid[static_cast<std::size_t>(gy * period + gx)] = lattice(s, gx, gy);
    auto g = [&](int gx, int gy) { return grid[static_cast<std::size_t>((gy % period_y) * period + gx % period)]; };
    for (int y = 0; y < h; ++y) {
      const double gy = y / cell_h;
      const int iy = static_cast<int>(gy);
      double ty = gy - iy;
      ty = ty * ty * (3 - 2 * ty);
      float* row = out.ptr<float>(y);
      for (int x = 0; x < w; ++x) {
        const double gx = x / cell_w;
        const int ix = static_cast<int>(gx);
        double tx = gx - ix;
        tx = tx * tx * (3 - 2 * tx);
        const float v00 = g(ix, iy), v10 = g(ix + 1, iy), v01 = g(ix, iy + 1), v11 = g(ix + 1, iy + 1);
        const double top = v00 + tx * (v10 - v00), bot = v01 + tx * (v11 - v01);
        row[x] += static_cast<float>(amp * (top + ty * (bot - top)));
      }
    }
    total += amp;
    amp *= persistence;
  }
  out /= static_cast<float>(total);
  return out;
}

cv::Mat plaster(int size, cv::Vec3b base, std::uint64_t seed) {
  return colorize(fbm(size, size, seed, 4, 7, 0.6), base, 0.35f);
}

cv::Mat plain(int size, cv::Vec3b base, std::uint64_t seed) {
  return colorize(fbm(size, size, seed, 2, 4, 0.5), base, 0.05f);
}

cv::Mat wood(int size, cv::Vec3b base, std::uint64_t seed) {
  const cv::Mat1f warp = fbm(size, size, seed, 2, 5, 0.55);
  const cv::Mat1f grain = fbm(size, size, seed + 7, 8, 4, 0.5);
  cv::Mat out(size, size, CV_8UC3);
  const int planks = 4;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const int plank = x * planks / size;
      const double rings = std::sin((y * 0.05 + 9.0 * warp(y, x) + plank * 1.7) * 3.0);
      float k = static_cast<float>(0.85 + 0.12 * rings + 0.25 * (grain(y, x) - 0.5) + 0.06 * ((plank * 37) % 5 - 2) / 2.0);
      if (x % (size / planks) < 2) k *= 0.55f;  // gap between planks
      out.at<cv::Vec3b>(y, x) = scale_color(base, k);
    }
  return out;
}

cv::Mat tiles(int size, int n_tiles, cv::Vec3b a, cv::Vec3b b, std::uint64_t seed) {
  const cv::Mat1f n = fbm(size, size, seed, 8, 5, 0.5);
  cv::Mat out(size, size, CV_8UC3);
  const int tile = size / n_tiles;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const int tx = x / tile, ty = y / tile;
      const cv::Vec3b c = ((tx + ty) % 2 == 0) ? a : b;
      const float var = 0.92f + 0.16f * lattice(seed, tx, ty);
      float k = var * (0.9f + 0.2f * n(y, x));
      if (x % tile < 2 || y % tile < 2) k *= 0.6f;  // grout
      out.at<cv::Vec3b>(y, x) = scale_color(c, k);
    }
  return out;
}

cv::Mat carpet(int size, cv::Vec3b base, std::uint64_t seed) {
  const cv::Mat1f coarse = fbm(size, size, seed, 3, 4, 0.5);
  const cv::Mat1f fine = fbm(size, size, seed + 3, 64, 2, 0.5);
  cv::Mat1f f = 0.6f * coarse + 0.4f * fine;
  return colorize(f, base, 0.5f);
}

cv::Mat poster(int w, int h, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> col(20, 235);
  auto rc = [&] { return cv::Scalar(col(rng), col(rng), col(rng)); };
  cv::Mat out(h, w, CV_8UC3, rc());
  // Background gradient from fbm so the poster is not flat.
  const cv::Mat1f bg = fbm(w, h, seed + 1, 2, 4, 0.5);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) out.at<cv::Vec3b>(y, x) = scale_color(out.at<cv::Vec3b>(y, x), 0.75f + 0.5f * bg(y, x));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int shapes = 25 + static_cast<int>(u(rng) * 30);
  for (int i = 0; i < shapes; ++i) {
    // Sizes follow a heavy tail (few large, many small shapes) like natural images.
    const double s = std::pow(u(rng), 2.5) * 0.4 * std::min(w, h) + 3;
    const cv::Point c(static_cast<int>(u(rng) * w), static_cast<int>(u(rng) * h));
    switch (static_cast<int>(u(rng) * 4)) {
      case 0: cv::circle(out, c, static_cast<int>(s), rc(), -1, cv::LINE_AA); break;
      case 1:
        cv::rectangle(out, cv::Rect(c.x, c.y, static_cast<int>(s * (0.5 + u(rng) * 1.5)), static_cast<int>(s)), rc(),
                      -1, cv::LINE_AA);
        break;
      case 2: {
        cv::ellipse(out, c, cv::Size(static_cast<int>(s), static_cast<int>(s * 0.4)), u(rng) * 180, 0, 360, rc(), -1,
                    cv::LINE_AA);
        break;
      }
      default: {
        // A block of "text" lines.
        const cv::Scalar ink = rc();
        for (int l = 0; l < 4; ++l)
          cv::rectangle(out, cv::Rect(c.x, c.y + l * 9, static_cast<int>(s * 2 * (0.6 + 0.4 * u(rng))), 4), ink, -1);
      }
    }
  }
  cv::rectangle(out, cv::Rect(0, 0, w, h), cv::Scalar(240, 240, 240), std::max(2, w / 40));  // white frame
  return out;
}

cv::Mat bookshelf(int w, int h, int shelves, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  cv::Mat out(h, w, CV_8UC3, cv::Scalar(40, 70, 100));
  const int shelf_h = h / shelves;
  for (int s = 0; s < shelves; ++s) {
    const int y0 = s * shelf_h, board = std::max(3, shelf_h / 10);
    cv::rectangle(out, cv::Rect(0, y0 + shelf_h - board, w, board), cv::Scalar(60, 100, 140), -1);
    int x = 3;
    while (x < w - 3) {
      const int bw = 4 + static_cast<int>(u(rng) * 12);
      const int bh = static_cast<int>(shelf_h * (0.55 + 0.35 * u(rng)));
      if (u(rng) < 0.08) {  // gap
        x += bw * 2;
        continue;
      }
      const cv::Scalar c(30 + u(rng) * 200, 30 + u(rng) * 200, 30 + u(rng) * 200);
      const cv::Rect r(x, y0 + shelf_h - board - bh, std::min(bw, w - 3 - x), bh);
      cv::rectangle(out, r, c, -1);
      cv::rectangle(out, cv::Rect(r.x, r.y + bh / 5, r.width, 2), c * 0.5, -1);  // label band
      x += bw + 1;
    }
  }
  return out;
}

cv::Mat fabric(int size, cv::Vec3b base, int pattern, std::uint64_t seed) {
  const cv::Mat1f n = fbm(size, size, seed, 4, 6, 0.55);
  cv::Mat out(size, size, CV_8UC3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      float k = 0.8f + 0.4f * n(y, x);
      if (pattern == 1 && (y / (size / 16)) % 2 == 0) k *= 0.55f;
      if (pattern == 2 && ((x / (size / 8)) + (y / (size / 8))) % 2 == 0) k *= 0.6f;
      if (((x + y) & 3) == 0) k *= 0.93f;  // weave
      out.at<cv::Vec3b>(y, x) = scale_color(base, k);
    }
  return out;
}

cv::Mat cardboard(int size, std::uint64_t seed) {
  cv::Mat out = colorize(fbm(size, size, seed, 4, 6, 0.5), cv::Vec3b(70, 130, 175), 0.35f);
  cv::rectangle(out, cv::Rect(0, size / 2 - size / 20, size, size / 10), cv::Scalar(90, 170, 200), -1);  // tape
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 6; ++i) {  // printed marks
    const cv::Point p(static_cast<int>(size * (0.1 + 0.8 * u(rng))), static_cast<int>(size * (0.1 + 0.8 * u(rng))));
    cv::putText(out, i % 2 ? "FRAGILE" : "THIS SIDE UP", p, cv::FONT_HERSHEY_SIMPLEX, 0.3 + u(rng) * 0.4,
                cv::Scalar(30, 30, 40), 2, cv::LINE_AA);
  }
  cv::circle(out, cv::Point(size / 4, size / 4), size / 10, cv::Scalar(30, 30, 40), 3, cv::LINE_AA);
  return out;
}

cv::Mat screen(int w, int h, std::uint64_t seed) {
  cv::Mat out = poster(w, h, seed);
  out *= 0.5;
  cv::rectangle(out, cv::Rect(0, 0, w, h), cv::Scalar(20, 20, 20), std::max(3, w / 20));
  return out;
}

}  // namespace texgen
}  // namespace varslam::synth
