#include "synth/renderer.hpp"

#include <algorithm>
#include <cmath>

namespace varslam::synth {

namespace {
constexpr int kTile = 16;
constexpr double kNear = 0.05;

// Pixel rectangle covered by a world box seen from the camera; false if off screen or behind the camera.
// The box is clipped against the near plane (corners in front plus edge crossings), so boxes that reach
// behind the camera do not flood every tile.
bool screen_rect(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Isometry3d& T_cw,
                 const PinholeCamera& cam, int& x0, int& y0, int& x1, int& y1) {
  Eigen::Vector3d pc[8];
  for (int i = 0; i < 8; ++i)
    pc[i] = T_cw * Eigen::Vector3d((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  double umin = 1e30, umax = -1e30, vmin = 1e30, vmax = -1e30;
  bool any = false;
  auto add = [&](const Eigen::Vector3d& p) {
    const double u = cam.fx * p.x() / p.z() + cam.cx, v = cam.fy * p.y() / p.z() + cam.cy;
    umin = std::min(umin, u), umax = std::max(umax, u), vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    any = true;
  };
  for (int i = 0; i < 8; ++i) {
    if (pc[i].z() >= kNear) add(pc[i]);
    for (int bit = 1; bit < 8; bit <<= 1) {  // the 12 edges: i -> i | bit for each unset bit
      if (i & bit) continue;
      const Eigen::Vector3d& a = pc[i];
      const Eigen::Vector3d& b = pc[i | bit];
      if ((a.z() < kNear) != (b.z() < kNear)) add(a + (kNear - a.z()) / (b.z() - a.z()) * (b - a));
    }
  }
  if (!any || umax < -1 || vmax < -1 || umin > cam.width || vmin > cam.height) return false;
  x0 = std::max(0, static_cast<int>(std::floor(std::max(umin, -1.0))) - 1);
  y0 = std::max(0, static_cast<int>(std::floor(std::max(vmin, -1.0))) - 1);
  x1 = std::min(cam.width - 1, static_cast<int>(std::ceil(std::min(umax, cam.width + 1.0))) + 1);
  y1 = std::min(cam.height - 1, static_cast<int>(std::ceil(std::min(vmax, cam.height + 1.0))) + 1);
  return true;
}

// Lower bound of the ray distance to anything inside the box (0 if the camera is inside).
double near_distance(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Vector3d& o) {
  return (lo - o).cwiseMax(o - hi).cwiseMax(0.0).norm();
}

struct Binned {
  double near;
  const Primitive* prim;
};
}  // namespace

Renderer::Renderer(const PinholeCamera& cam) : cam_(cam) {
  rays_.resize(static_cast<std::size_t>(cam.width * cam.height));
  z_per_t_.resize(rays_.size());
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d d((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
      const std::size_t i = static_cast<std::size_t>(v * cam.width + u);
      rays_[i] = d.normalized();
      z_per_t_[i] = 1.0 / d.norm();
    }
}

void Renderer::render(const Scene& scene, const std::vector<Primitive>& dynamic, const Eigen::Isometry3d& T_wc,
                      RenderOutput& out) const {
  const int W = cam_.width, H = cam_.height;
  out.color.create(H, W);
  out.depth.create(H, W);
  out.ids.create(H, W);
  const Eigen::Isometry3d T_cw = T_wc.inverse();
  const Eigen::Matrix3d R = T_wc.rotation();
  const Eigen::Vector3d o = T_wc.translation();

  // Bin primitives into screen tiles.
  const int tw = (W + kTile - 1) / kTile, th = (H + kTile - 1) / kTile;
  std::vector<std::vector<Binned>> tiles(static_cast<std::size_t>(tw * th));
  auto bin = [&](const Primitive& p) {
    Eigen::Vector3d lo, hi;
    p.bounds(lo, hi);
    int x0, y0, x1, y1;
    if (!screen_rect(lo, hi, T_cw, cam_, x0, y0, x1, y1)) return;
    const double near = near_distance(lo, hi, o);
    for (int ty = y0 / kTile; ty <= y1 / kTile; ++ty)
      for (int tx = x0 / kTile; tx <= x1 / kTile; ++tx)
        tiles[static_cast<std::size_t>(ty * tw + tx)].push_back({near, &p});
  };
  for (const auto& p : scene.statics) bin(p);
  for (const auto& p : dynamic) bin(p);
  // Front to back: a pixel stops testing once the next primitive cannot be nearer than its hit.
  for (auto& t : tiles) std::sort(t.begin(), t.end(), [](const Binned& a, const Binned& b) { return a.near < b.near; });

  const double pixel_angle = 1.0 / cam_.fx;
  for (int ty = 0; ty < th; ++ty)
    for (int tx = 0; tx < tw; ++tx) {
      const auto& list = tiles[static_cast<std::size_t>(ty * tw + tx)];
      for (int v = ty * kTile; v < std::min(H, (ty + 1) * kTile); ++v) {
        auto* crow = out.color.ptr<cv::Vec3f>(v);
        auto* drow = out.depth.ptr<float>(v);
        auto* irow = out.ids.ptr<uchar>(v);
        for (int u = tx * kTile; u < std::min(W, (tx + 1) * kTile); ++u) {
          const std::size_t pi = static_cast<std::size_t>(v * W + u);
          const Eigen::Vector3d d = R * rays_[pi];
          Hit hit;
          int axis, side;
          hit.t = exit_box(scene.room_lo, scene.room_hi, o, d, axis, side);
          hit.n = Eigen::Vector3d::Zero();
          hit.n[axis] = side ? 1.0 : -1.0;
          const Eigen::Vector3d q = o + hit.t * d - scene.room_lo;
          hit.uv = axis == 0 ? Eigen::Vector2d(q.z(), q.y())
                             : axis == 1 ? Eigen::Vector2d(q.x(), q.z()) : Eigen::Vector2d(q.x(), q.y());
          hit.material = scene.face_material[axis][side];
          hit.object_id = kStaticId;
          Hit cand;
          for (const Binned& b : list) {
            if (b.near >= hit.t) break;
            if (intersect(*b.prim, o, d, 1e-4, hit.t, cand)) hit = cand;
          }

          const Eigen::Vector3d pw = o + hit.t * d;
          Eigen::Vector3d n = hit.n;
          double cos_view = n.dot(d);
          if (cos_view > 0) {
            n = -n;
          } else {
            cos_view = -cos_view;
          }
          const Material& m = scene.materials[static_cast<std::size_t>(hit.material)];
          // Pixel footprint on the surface in texels; grazing angles widen it (clamped: no anisotropy).
          const double footprint = hit.t * pixel_angle / std::max(cos_view, 0.3) / m.texel_m;
          const cv::Vec3f albedo =
              scene.textures[static_cast<std::size_t>(m.texture)].sample(hit.uv.x() / m.texel_m, hit.uv.y() / m.texel_m,
                                                                         footprint);
          double light = 0.38;
          for (const auto& L : scene.lights) {
            const Eigen::Vector3d l = L - pw;
            const double dist2 = l.squaredNorm();
            light += 0.55 * std::max(0.0, n.dot(l) / std::sqrt(dist2)) / (1.0 + 0.03 * dist2);
          }
          crow[u] = albedo * static_cast<float>(light);
          drow[u] = static_cast<float>(hit.t * z_per_t_[pi]);
          irow[u] = hit.object_id;
        }
      }
    }
}

}  // namespace varslam::synth
