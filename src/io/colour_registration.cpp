#include "io/colour_registration.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace varslam {
namespace {

struct FrameEdges {
  std::vector<cv::Point2f> points;  // depth-edge pixels
  std::vector<float> inverse_depth;  // 1 / z of each, 1/m
  cv::Mat gradient;                 // CV_32F colour gradient magnitude, mean 1
};

// Blurred so that a mapping one or two pixels off still scores, which keeps the coarse search smooth.
cv::Mat normalised_gradient(const cv::Mat& gray) {
  cv::Mat g, gx, gy, mag;
  gray.convertTo(g, CV_32F);
  cv::GaussianBlur(g, g, cv::Size(5, 5), 1.5);
  cv::Sobel(g, gx, CV_32F, 1, 0);
  cv::Sobel(g, gy, CV_32F, 0, 1);
  cv::magnitude(gx, gy, mag);
  const double mean = cv::mean(mag)[0];
  return mean > 0 ? mag / mean : mag;
}

struct Mapping {
  double scale, du, dv;
  double tx = 0.0;  // the depth camera's x in the colour frame (m): a parallax of colour fx * tx / z pixels
};

// Nearest pixel index of a coordinate, -1 when it rounds below 0 (no library call: this runs ~10^8 times).
int nearest_index(double x) { return x < -0.5 ? -1 : static_cast<int>(x + 0.5); }

// Over every `stride`-th edge point.
double mean_gradient(const std::vector<FrameEdges>& frames, const PinholeCamera& d, const Mapping& m,
                     std::size_t stride = 1) {
  const double parallax_per_inverse_depth = m.scale * d.fx * m.tx;
  double sum = 0.0;
  long n = 0;
  for (const FrameEdges& f : frames) {
    const cv::Mat& g = f.gradient;
    for (std::size_t i = 0; i < f.points.size(); i += stride) {
      const cv::Point2f& p = f.points[i];
      const double parallax = parallax_per_inverse_depth * f.inverse_depth[i];
      const int u = nearest_index(m.scale * (p.x - d.cx) + d.cx + m.du + parallax);
      const int v = nearest_index(m.scale * (p.y - d.cy) + d.cy + m.dv);
      if (u < 0 || v < 0 || u >= g.cols || v >= g.rows) continue;
      sum += g.ptr<float>(v)[u];
      ++n;
    }
  }
  return n > 0 ? sum / static_cast<double>(n) : 0.0;
}

struct Grid {
  int scale_steps;
  double scale_step;
  int shift_steps;
  double shift_step;
};

// Best mapping over a grid of scales and shifts centred on `c` (its baseline kept).
Mapping grid_search(const std::vector<FrameEdges>& frames, const PinholeCamera& d, const Mapping& c, const Grid& g,
                    std::size_t stride, double& best_score) {
  Mapping best = c;
  best_score = -1.0;
  for (int i = -g.scale_steps; i <= g.scale_steps; ++i)
    for (int j = -g.shift_steps; j <= g.shift_steps; ++j)
      for (int k = -g.shift_steps; k <= g.shift_steps; ++k) {
        const Mapping m{c.scale + i * g.scale_step, c.du + j * g.shift_step, c.dv + k * g.shift_step, c.tx};
        const double s = mean_gradient(frames, d, m, stride);
        if (s > best_score) best_score = s, best = m;
      }
  return best;
}

double mean_inverse_depth(const std::vector<FrameEdges>& frames) {
  double sum = 0.0;
  std::size_t n = 0;
  for (const FrameEdges& f : frames)
    for (const float w : f.inverse_depth) sum += w, ++n;
  return n > 0 ? sum / static_cast<double>(n) : 0.0;
}

// The baseline shifts near edges more than far ones. A shift alone fits it at one depth; sweeping the baseline with
// the shift moved to keep the mean edge in place, then refining around the best, fits it at every depth.
Mapping baseline_search(const std::vector<FrameEdges>& frames, const PinholeCamera& d, const Mapping& no_baseline,
                        const ColourRegistrationSearch& search, std::size_t coarse_stride, double& best_score) {
  const double w = mean_inverse_depth(frames);
  const int steps = static_cast<int>(std::ceil(search.max_baseline_m / search.baseline_step_m));
  Mapping best = no_baseline;
  best_score = -1.0;
  for (int i = -steps; i <= steps; ++i) {
    Mapping c = no_baseline;
    c.tx = i * search.baseline_step_m;
    c.du -= c.scale * d.fx * c.tx * w;
    double s = 0.0;
    const Mapping m = grid_search(frames, d, c, {1, 0.0025, 2, 1.0}, coarse_stride, s);
    if (s > best_score) best_score = s, best = m;
  }
  Mapping fine = best;
  best_score = -1.0;
  for (const double half_steps : {-1.0, 0.0, 1.0}) {
    Mapping c = best;
    c.tx += 0.5 * half_steps * search.baseline_step_m;
    c.du -= c.scale * d.fx * (c.tx - best.tx) * w;
    double s = 0.0;
    const Mapping m = grid_search(frames, d, c, {2, 0.00125, 2, 0.5}, 1, s);
    if (s > best_score) best_score = s, fine = m;
  }
  return fine;
}

}  // namespace

PinholeCamera ColourRegistration::colour_camera(const PinholeCamera& depth) const {
  PinholeCamera c = depth;
  c.fx = scale * depth.fx;
  c.fy = scale * depth.fy;
  c.cx = depth.cx + du;
  c.cy = depth.cy + dv;
  c.bf = scale * depth.bf;  // same baseline in metres
  return c;
}

std::vector<cv::Point> occluding_edge_pixels(const cv::Mat& depth_m, double rel_jump, double abs_jump) {
  CV_Assert(depth_m.type() == CV_32FC1);
  std::vector<cv::Point> out;
  const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
  for (int v = 2; v < depth_m.rows - 2; ++v)
    for (int u = 2; u < depth_m.cols - 2; ++u) {
      const float z = depth_m.at<float>(v, u);
      if (!(z > 0.0f)) continue;
      for (int k = 0; k < 4; ++k) {
        const float n = depth_m.at<float>(v + dv[k], u + du[k]);
        if (n > 0.0f && n > z * (1.0 + rel_jump) + abs_jump) {
          out.emplace_back(u, v);
          break;
        }
      }
    }
  return out;
}

ColourRegistration estimate_colour_registration(const std::vector<cv::Mat>& grays, const std::vector<cv::Mat>& depths_m,
                                                const PinholeCamera& depth_camera,
                                                const ColourRegistrationSearch& search) {
  if (grays.size() != depths_m.size())
    throw std::invalid_argument("estimate_colour_registration: as many gray images as depth images needed");
  std::vector<FrameEdges> frames;
  ColourRegistration r;
  for (std::size_t i = 0; i < grays.size(); ++i) {
    const std::vector<cv::Point> edges = occluding_edge_pixels(depths_m[i]);
    if (edges.empty()) continue;
    FrameEdges f;
    const std::size_t stride = std::max<std::size_t>(1, edges.size() / static_cast<std::size_t>(search.points_per_frame));
    for (std::size_t k = 0; k < edges.size(); k += stride) {
      f.points.emplace_back(edges[k]);
      f.inverse_depth.push_back(1.0f / depths_m[i].at<float>(edges[k]));
    }
    f.gradient = normalised_gradient(grays[i]);
    r.edge_points += static_cast<int>(f.points.size());
    frames.push_back(std::move(f));
  }
  r.frames = static_cast<int>(frames.size());
  if (frames.empty()) return r;

  r.identity_score = mean_gradient(frames, depth_camera, {1.0, 0.0, 0.0});
  // Coarse (1 % of scale, 2 px, ~5000 points: 3549 mappings), then fine (0.25 %, 1 px, all points) around the best.
  const std::size_t coarse_stride = std::max<std::size_t>(1, static_cast<std::size_t>(r.edge_points) / 5000);
  const double mid = 0.5 * (search.min_scale + search.max_scale);
  const int coarse_scales = static_cast<int>(std::ceil((search.max_scale - search.min_scale) / 0.02));
  double score = 0.0;
  Mapping best = grid_search(frames, depth_camera, {mid, 0.0, 0.0}, {coarse_scales, 0.01, search.max_shift_px / 2, 2.0},
                             coarse_stride, score);
  best = grid_search(frames, depth_camera, best, {6, 0.0025, 2, 1.0}, 1, score);
  if (search.max_baseline_m > 0.0) {
    double with_baseline_score = 0.0;
    const Mapping with_baseline =
        baseline_search(frames, depth_camera, best, search, coarse_stride, with_baseline_score);
    if (with_baseline_score > score) best = with_baseline, score = with_baseline_score;
  }
  r.scale = best.scale;
  r.du = best.du;
  r.dv = best.dv;
  r.baseline_x = best.tx;
  r.score = score;
  // How far the mapping moves the farthest image corner from where identity puts it.
  double change = 0.0;
  for (const double u : {0.0, static_cast<double>(depth_camera.width)})
    for (const double v : {0.0, static_cast<double>(depth_camera.height)})
      change = std::max(change, std::hypot((r.scale - 1.0) * (u - depth_camera.cx) + r.du,
                                           (r.scale - 1.0) * (v - depth_camera.cy) + r.dv));
  r.found = r.identity_score > 0 && r.score >= search.min_gain * r.identity_score && change >= search.min_change_px;
  return r;
}

}  // namespace varslam
