#include "slam/frame.hpp"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>

namespace varslam::slam {

std::vector<int> FrameFeatures::in_area(double u, double v, double r, int min_level, int max_level) const {
  std::vector<int> out;
  const double cell_w = static_cast<double>(camera.width) / kGridCols;
  const double cell_h = static_cast<double>(camera.height) / kGridRows;
  const int c0 = std::max(0, static_cast<int>(std::floor((u - r) / cell_w)));
  const int c1 = std::min(kGridCols - 1, static_cast<int>(std::floor((u + r) / cell_w)));
  const int r0 = std::max(0, static_cast<int>(std::floor((v - r) / cell_h)));
  const int r1 = std::min(kGridRows - 1, static_cast<int>(std::floor((v + r) / cell_h)));
  if (c0 > c1 || r0 > r1) return out;
  const double r2 = r * r;
  for (int gy = r0; gy <= r1; ++gy)
    for (int gx = c0; gx <= c1; ++gx)
      for (int idx : grid[gy * kGridCols + gx]) {
        const cv::KeyPoint& kp = keypoints[idx];
        if (min_level >= 0 && kp.octave < min_level) continue;
        if (max_level >= 0 && kp.octave > max_level) continue;
        const double dx = kp.pt.x - u, dy = kp.pt.y - v;
        if (dx * dx + dy * dy <= r2) out.push_back(idx);
      }
  return out;
}

Eigen::Vector3d FrameFeatures::unproject(std::size_t i) const {
  return camera.unproject(keypoints[i].pt.x, keypoints[i].pt.y, depth[i]);
}

void FrameFeatures::build_grid() {
  grid.assign(kGridCols * kGridRows, {});
  const double sx = static_cast<double>(kGridCols) / camera.width;
  const double sy = static_cast<double>(kGridRows) / camera.height;
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    const int gx = static_cast<int>(keypoints[i].pt.x * sx);
    const int gy = static_cast<int>(keypoints[i].pt.y * sy);
    if (gx < 0 || gy < 0 || gx >= kGridCols || gy >= kGridRows) continue;
    grid[gy * kGridCols + gx].push_back(static_cast<int>(i));
  }
}

std::shared_ptr<FrameFeatures> make_frame_features(std::vector<cv::KeyPoint> keypoints, cv::Mat descriptors,
                                                   const cv::Mat& depth_m, const PinholeCamera& camera,
                                                   double close_depth, std::shared_ptr<const ScaleInfo> scale,
                                                   double depth_edge_ratio) {
  auto f = std::make_shared<FrameFeatures>();
  f->camera = camera;
  f->close_depth = close_depth;
  f->scale = std::move(scale);
  f->descriptors = std::move(descriptors);
  const std::size_t n = keypoints.size();
  f->depth.assign(n, -1.0f);
  f->u_right.assign(n, -1.0f);
  f->on_depth_edge.assign(n, 0);
  // Depth is looked up at the distorted pixel (where the sensor measured it), then positions are undistorted.
  for (std::size_t i = 0; i < n; ++i) {
    const int u = static_cast<int>(std::lround(keypoints[i].pt.x));
    const int v = static_cast<int>(std::lround(keypoints[i].pt.y));
    if (!depth_m.empty() && u >= 0 && v >= 0 && u < depth_m.cols && v < depth_m.rows) {
      const float d = depth_m.at<float>(v, u);
      if (d > 0.0f && std::isfinite(d)) {
        if (depth_edge_ratio > 0 && on_depth_edge(depth_m, u, v, d, depth_edge_ratio)) {
          ++f->depth_edge_rejected;
          f->on_depth_edge[i] = 1;
        } else {
          f->depth[i] = d;
        }
      }
    }
  }
  if (camera.has_distortion() && n > 0) {
    std::vector<cv::Point2f> pts(n);
    for (std::size_t i = 0; i < n; ++i) pts[i] = keypoints[i].pt;
    const std::vector<cv::Point2f> und = undistort_pixels(camera, pts);
    for (std::size_t i = 0; i < n; ++i) keypoints[i].pt = und[i];
  }
  for (std::size_t i = 0; i < n; ++i)
    if (f->depth[i] > 0.0f) f->u_right[i] = static_cast<float>(keypoints[i].pt.x - camera.bf / f->depth[i]);
  f->keypoints = std::move(keypoints);
  f->build_grid();
  return f;
}

bool on_depth_edge(const cv::Mat& depth_m, int u, int v, float d, double ratio, int r) {
  float lo = d, hi = d;
  for (int y = std::max(0, v - r); y <= std::min(depth_m.rows - 1, v + r); ++y) {
    const float* row = depth_m.ptr<float>(y);
    for (int x = std::max(0, u - r); x <= std::min(depth_m.cols - 1, u + r); ++x) {
      const float z = row[x];
      if (z <= 0.0f) continue;
      lo = std::min(lo, z);
      hi = std::max(hi, z);
    }
  }
  return hi - lo > ratio * d;
}

int Frame::num_tracked() const {
  int n = 0;
  for (std::size_t i = 0; i < map_points.size(); ++i)
    if (map_points[i] && !outlier[i] && !map_points[i]->is_bad()) ++n;
  return n;
}

int Frame::num_established(int min_found) const {
  int n = 0;
  for (std::size_t i = 0; i < map_points.size(); ++i) {
    const MapPointPtr& mp = map_points[i];
    if (mp && !outlier[i] && !mp->is_bad() && mp->is_established(id, min_found, 0)) ++n;
  }
  return n;
}

}  // namespace varslam::slam
