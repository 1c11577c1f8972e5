#include "synth/scene.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace varslam::synth {

int Scene::add_texture(const cv::Mat& bgr) {
  textures.emplace_back(bgr);
  return static_cast<int>(textures.size()) - 1;
}

int Scene::add_material(int texture, double texel_m, std::string name) {
  materials.push_back(Material{texture, texel_m, std::move(name)});
  return static_cast<int>(materials.size()) - 1;
}

namespace {

Primitive box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int material, int top = -1) {
  Primitive p;
  p.shape = Shape::Aabb;
  p.a = lo.cwiseMin(hi);
  p.b = lo.cwiseMax(hi);
  p.material = material;
  p.top_material = top;
  return p;
}

struct Footprint {
  double x0, z0, x1, z1;
  bool overlaps(const Footprint& o, double margin) const {
    return x0 - margin < o.x1 && o.x0 - margin < x1 && z0 - margin < o.z1 && o.z0 - margin < z1;
  }
};

class Builder {
 public:
  Builder(Scene& s, const ViewAnchor& a, const std::vector<KeepOut>& k, std::uint64_t seed)
      : scene_(s), anchor_(a), keep_(k), rng_(seed), seed_(seed) {}

  void build() {
    make_materials();
    make_room_decor();
    place_furniture();
    const double ceil_y = scene_.room_lo.y() + 0.3;
    scene_.lights.push_back(Eigen::Vector3d(anchor_.center.x(), ceil_y, anchor_.center.z()) + 1.5 * anchor_.forward);
    scene_.lights.push_back(Eigen::Vector3d(anchor_.center.x(), ceil_y, anchor_.center.z()) - 1.0 * anchor_.forward +
                            1.5 * anchor_.right);
  }

 private:
  double uni(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  std::uint64_t sub() { return rng_(); }
  cv::Vec3b color(int lo, int hi) {
    return cv::Vec3b(static_cast<uchar>(uni(lo, hi)), static_cast<uchar>(uni(lo, hi)), static_cast<uchar>(uni(lo, hi)));
  }

  void make_materials() {
    Scene& s = scene_;
    const int wall_a = s.add_texture(texgen::plaster(512, cv::Vec3b(190, 200, 205), sub()));
    const int wall_b = s.add_texture(texgen::plaster(512, cv::Vec3b(150, 185, 200), sub()));
    const int ceiling = s.add_texture(texgen::plain(256, cv::Vec3b(225, 228, 230), sub()));
    const bool tiled = uni(0, 1) < 0.5;
    const int floor = tiled ? s.add_texture(texgen::tiles(512, 8, cv::Vec3b(150, 160, 165), cv::Vec3b(120, 130, 140), sub()))
                            : s.add_texture(texgen::wood(512, cv::Vec3b(70, 115, 160), sub()));
    wall_mat_[0] = s.add_material(wall_a, 0.006, "wall plaster");
    wall_mat_[1] = s.add_material(wall_b, 0.006, "wall plaster (tinted)");
    const int ceil_mat = s.add_material(ceiling, 0.02, "plain ceiling");
    const int floor_mat = s.add_material(floor, tiled ? 0.005 : 0.004, tiled ? "floor tiles" : "wood floor");
    s.face_material[0][0] = wall_mat_[0];
    s.face_material[0][1] = wall_mat_[1];
    s.face_material[2][0] = wall_mat_[1];
    s.face_material[2][1] = wall_mat_[0];
    s.face_material[1][0] = ceil_mat;
    s.face_material[1][1] = floor_mat;
    table_wood_ = s.add_material(s.add_texture(texgen::wood(512, cv::Vec3b(60, 110, 150), sub())), 0.002, "table wood");
    dark_wood_ = s.add_material(s.add_texture(texgen::wood(512, cv::Vec3b(40, 60, 90), sub())), 0.0025, "dark wood");
    painted_ = s.add_material(s.add_texture(texgen::plaster(256, cv::Vec3b(110, 140, 90), sub())), 0.004, "painted");
    metal_ = s.add_material(s.add_texture(texgen::plain(256, cv::Vec3b(90, 90, 95), sub())), 0.01, "metal");
    cardboard_tex_ = s.add_texture(texgen::cardboard(256, sub()));
    white_ = s.add_material(s.add_texture(texgen::plain(256, cv::Vec3b(240, 242, 242), sub())), 0.01, "whiteboard");
    rug_ = s.add_material(s.add_texture(texgen::carpet(256, color(60, 160), sub())), 0.006, "rug");
  }

  // Thin panel on a room wall (posters, whiteboard), 2 cm off the wall.
  void wall_panel(int axis, int side, double along_center, double y_center, double w, double h, int material) {
    const Eigen::Vector3d& lo = scene_.room_lo;
    const Eigen::Vector3d& hi = scene_.room_hi;
    const double wall = side ? hi[axis] : lo[axis];
    const double inward = side ? -1.0 : 1.0;
    const int other = axis == 0 ? 2 : 0;
    Eigen::Vector3d a, b;
    a[axis] = wall + inward * 0.02;
    b[axis] = wall + inward * 0.03;
    a[other] = along_center - w / 2;
    b[other] = along_center + w / 2;
    a.y() = y_center - h / 2;
    b.y() = y_center + h / 2;
    scene_.statics.push_back(box(a, b, material));
  }

  void make_room_decor() {
    const Eigen::Vector3d& lo = scene_.room_lo;
    const Eigen::Vector3d& hi = scene_.room_hi;
    const double floor = hi.y();
    bool whiteboard_done = false;
    for (int axis : {0, 2})
      for (int side : {0, 1}) {
        const int other = axis == 0 ? 2 : 0;
        const double len = hi[other] - lo[other];
        // The wall the camera faces gets more: with the middle of the room kept free for the movers of every
        // scenario, it is most of what the camera sees.
        const int n = (facing_camera(axis, side) ? 6 : 3) + static_cast<int>(uni(0, 2.99));
        for (int i = 0; i < n; ++i) {
          const double slot = lo[other] + len * (i + 0.5) / n + uni(-0.2, 0.2) * len / n;
          if (!whiteboard_done && i == 0 && facing_camera(axis, side)) {
            wall_panel(axis, side, slot, floor - 1.45, 1.6, 1.0, white_);
            whiteboard_done = true;
            continue;
          }
          // Posters: portrait or landscape, texture sized so it maps exactly once.
          const bool portrait = uni(0, 1) < 0.5;
          const double w = portrait ? uni(0.5, 0.7) : uni(0.8, 1.2);
          const double h = portrait ? w * 2.0 * uni(0.65, 0.75) : w * 0.5 * uni(1.1, 1.3);
          const int tw = portrait ? 256 : 512, th = 256;
          const int tex = scene_.add_texture(texgen::poster(tw, th, sub()));
          const double texel = w / tw;
          const double hh = th * texel;  // keep aspect of the texture
          (void)h;
          wall_panel(axis, side, slot, floor - uni(1.4, 1.7), w, hh, scene_.add_material(tex, texel, "poster"));
        }
      }
  }

  bool facing_camera(int axis, int side) const {
    const double f = anchor_.forward[axis];
    return (side == 1 && f > 0.5) || (side == 0 && f < -0.5);
  }

  bool free_spot(const Footprint& fp) const {
    const Eigen::Vector3d& lo = scene_.room_lo;
    const Eigen::Vector3d& hi = scene_.room_hi;
    if (fp.x0 < lo.x() + 0.05 || fp.x1 > hi.x() - 0.05 || fp.z0 < lo.z() + 0.05 || fp.z1 > hi.z() - 0.05) return false;
    for (const auto& k : keep_) {
      const double cx = std::clamp(k.xz.x(), fp.x0, fp.x1), cz = std::clamp(k.xz.y(), fp.z0, fp.z1);
      if (std::hypot(cx - k.xz.x(), cz - k.xz.y()) < k.radius) return false;
    }
    for (const auto& o : placed_)
      if (fp.overlaps(o, 0.25)) return false;
    return true;
  }

  void table(const Footprint& fp) {
    const double floor = scene_.room_hi.y(), top = floor - 0.74;
    scene_.statics.push_back(box({fp.x0, top, fp.z0}, {fp.x1, top + 0.04, fp.z1}, table_wood_));
    const double l = 0.05;
    for (int i = 0; i < 4; ++i) {
      const double x = (i & 1) ? fp.x1 - l - 0.03 : fp.x0 + 0.03, z = (i & 2) ? fp.z1 - l - 0.03 : fp.z0 + 0.03;
      scene_.statics.push_back(box({x, top + 0.04, z}, {x + l, floor, z + l}, metal_));
    }
    // Things on the table: a monitor, a cardboard box, a stack of books.
    const double cx = 0.5 * (fp.x0 + fp.x1), cz = 0.5 * (fp.z0 + fp.z1);
    const bool along_x = (fp.x1 - fp.x0) > (fp.z1 - fp.z0);
    if (uni(0, 1) < 0.7) {
      const int tex = scene_.add_texture(texgen::screen(256, 128, sub()));
      const double w = 0.55, h = 0.34;
      const int mat = scene_.add_material(tex, w / 256, "monitor");
      Eigen::Vector3d a(cx - (along_x ? w / 2 : 0.02), top - 0.1 - h, cz - (along_x ? 0.02 : w / 2));
      Eigen::Vector3d b(cx + (along_x ? w / 2 : 0.02), top - 0.1, cz + (along_x ? 0.02 : w / 2));
      scene_.statics.push_back(box(a, b, mat, metal_));
      scene_.statics.push_back(box({cx - 0.03, top - 0.1, cz - 0.03}, {cx + 0.03, top, cz + 0.03}, metal_));
    }
    if (uni(0, 1) < 0.7) {
      const double s = uni(0.2, 0.35);
      const double x = along_x ? fp.x0 + 0.1 : cx + 0.05, z = along_x ? cz + 0.05 : fp.z0 + 0.1;
      scene_.statics.push_back(box({x, top - s, z}, {x + s, top, z + s * 0.8}, cardboard(s)));
    }
    if (uni(0, 1) < 0.6) {
      const double x = along_x ? fp.x1 - 0.35 : cx - 0.2, z = along_x ? cz - 0.2 : fp.z1 - 0.35;
      double y = top;
      for (int i = 0; i < 3; ++i) {
        const double t = uni(0.03, 0.06);
        scene_.statics.push_back(box({x + uni(0, 0.03), y - t, z}, {x + 0.25, y, z + 0.18}, i % 2 ? painted_ : dark_wood_));
        y -= t;
      }
    }
    placed_.push_back(fp);
  }

  int cardboard(double size) { return scene_.add_material(cardboard_tex_, size / 256, "cardboard"); }

  // Bookcase: books on the sides, wooden top. Texel size makes the shelf texture span the longer side once.
  void bookcase(const Footprint& fp, double height) {
    const double floor = scene_.room_hi.y();
    const double w = std::max(fp.x1 - fp.x0, fp.z1 - fp.z0);
    const int tex = scene_.add_texture(texgen::bookshelf(256, 512, 5, sub()));
    const int mat = scene_.add_material(tex, w / 256, "books");
    const double h = std::min(height, 512 * (w / 256));
    scene_.statics.push_back(box({fp.x0, floor - h, fp.z0}, {fp.x1, floor, fp.z1}, mat, dark_wood_));
    placed_.push_back(fp);
  }

  void place_furniture() {
    const double floor = scene_.room_hi.y();
    int placed = 0, tries = 0;
    const int wanted = 9 + static_cast<int>(uni(0, 4));
    while (placed < wanted && tries < 400) {
      ++tries;
      // Mostly in front of the camera (1-4 m), some anywhere in the room.
      Eigen::Vector3d c;
      if (uni(0, 1) < 0.8) {
        c = anchor_.center + uni(1.0, 4.2) * anchor_.forward + uni(-2.8, 2.8) * anchor_.right;
      } else {
        c = {uni(scene_.room_lo.x(), scene_.room_hi.x()), 0, uni(scene_.room_lo.z(), scene_.room_hi.z())};
      }
      const double kind = uni(0, 1);
      double sx, sz;
      if (kind < 0.35) {
        sx = uni(1.1, 1.6), sz = uni(0.7, 0.9);
      } else if (kind < 0.6) {
        sx = uni(0.8, 1.0), sz = 0.35;
      } else if (kind < 0.8) {
        sx = uni(0.6, 1.0), sz = 0.5;
      } else {
        sx = sz = uni(0.35, 0.6);
      }
      if (uni(0, 1) < 0.5) std::swap(sx, sz);
      const Footprint fp{c.x() - sx / 2, c.z() - sz / 2, c.x() + sx / 2, c.z() + sz / 2};
      if (!free_spot(fp)) continue;
      if (kind < 0.35) {
        table(fp);
      } else if (kind < 0.6) {
        bookcase(fp, uni(1.6, 2.0));
      } else if (kind < 0.8) {
        const double h = uni(0.8, 1.2);
        scene_.statics.push_back(box({fp.x0, floor - h, fp.z0}, {fp.x1, floor, fp.z1}, painted_, table_wood_));
        placed_.push_back(fp);
      } else {
        // Stack of cardboard boxes.
        double y = floor;
        const double s = fp.x1 - fp.x0;
        for (int i = 0, n = 1 + static_cast<int>(uni(0, 2.99)); i < n; ++i) {
          const double si = s * (1.0 - 0.15 * i), h = si * uni(0.6, 0.9), off = 0.5 * (s - si);
          scene_.statics.push_back(box({fp.x0 + off, y - h, fp.z0 + off}, {fp.x0 + off + si, y, fp.z0 + off + si}, cardboard(si)));
          y -= h;
        }
        placed_.push_back(fp);
      }
      ++placed;
    }
    // The movers of every scenario keep the middle of the room free (the room must not depend on the scenario),
    // so fill up along the walls, where real rooms keep their shelves: bookcases and cabinets backed onto a wall.
    // Mostly the wall the camera faces: what it sees behind the movers.
    int along_walls = 0;
    for (tries = 0; along_walls < 4 && tries < 300; ++tries) {
      int axis = uni(0, 1) < 0.5 ? 0 : 2, side = uni(0, 1) < 0.5 ? 0 : 1;
      if (uni(0, 1) < 0.75)
        for (int a : {0, 2})
          for (int sd : {0, 1})
            if (facing_camera(a, sd)) axis = a, side = sd;
      const int other = axis == 0 ? 2 : 0;
      const double depth = uni(0.3, 0.45), width = uni(0.7, 1.2);
      const double wall = side == 0 ? scene_.room_lo[axis] + 0.06 : scene_.room_hi[axis] - 0.06 - depth;
      const double along = uni(scene_.room_lo[other] + 0.1, scene_.room_hi[other] - 0.1 - width);
      Eigen::Vector2d lo, hi;  // (x, z)
      lo[axis == 0 ? 0 : 1] = wall;
      hi[axis == 0 ? 0 : 1] = wall + depth;
      lo[other == 0 ? 0 : 1] = along;
      hi[other == 0 ? 0 : 1] = along + width;
      const Footprint fp{lo.x(), lo.y(), hi.x(), hi.y()};
      if (!free_spot(fp)) continue;
      if (uni(0, 1) < 0.65) {
        bookcase(fp, uni(1.6, 2.0));
      } else {
        const double h = uni(0.8, 1.2);
        scene_.statics.push_back(box({fp.x0, floor - h, fp.z0}, {fp.x1, floor, fp.z1}, painted_, table_wood_));
        placed_.push_back(fp);
      }
      ++along_walls;
    }
    // A rug under the action area (low texture variation, on the floor).
    const Eigen::Vector3d rc = anchor_.center + 2.5 * anchor_.forward;
    scene_.statics.push_back(box({rc.x() - 1.2, floor - 0.01, rc.z() - 0.8}, {rc.x() + 1.2, floor - 0.001, rc.z() + 0.8}, rug_));
  }

  Scene& scene_;
  const ViewAnchor& anchor_;
  const std::vector<KeepOut>& keep_;
  std::mt19937_64 rng_;
  std::uint64_t seed_;
  std::vector<Footprint> placed_;
  int wall_mat_[2] = {0, 0};
  int table_wood_ = 0, dark_wood_ = 0, painted_ = 0, metal_ = 0, cardboard_tex_ = 0, white_ = 0, rug_ = 0;
};

}  // namespace

Scene build_static_scene(const Eigen::Vector3d& room_lo, const Eigen::Vector3d& room_hi, const ViewAnchor& anchor,
                         const std::vector<KeepOut>& keep_out, std::uint64_t seed) {
  Scene s;
  s.room_lo = room_lo;
  s.room_hi = room_hi;
  s.floor_y = room_hi.y();
  Builder(s, anchor, keep_out, seed).build();
  return s;
}

}  // namespace varslam::synth
