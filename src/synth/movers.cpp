#include "synth/movers.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "synth/fast_rng.hpp"

namespace varslam::synth {

namespace {

// Position along a polyline walked back and forth (ping-pong) at arc length s; dir = unit walking direction.
template <typename V>
V ping_pong(const std::vector<V>& pts, double s, V& dir) {
  double total = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) total += (pts[i] - pts[i - 1]).norm();
  if (total <= 0 || pts.size() < 2) {
    dir = V::Zero();
    return pts.front();
  }
  s = std::fmod(s, 2 * total);
  if (s < 0) s += 2 * total;
  const bool back = s > total;
  if (back) s = 2 * total - s;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const double len = (pts[i] - pts[i - 1]).norm();
    if (s <= len || i + 1 == pts.size()) {
      dir = (pts[i] - pts[i - 1]) / std::max(len, 1e-9);
      if (back) dir = -dir;
      return pts[i - 1] + std::min(s, len) * (pts[i] - pts[i - 1]) / std::max(len, 1e-9);
    }
    s -= len;
  }
  return pts.back();
}

Primitive capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r, int mat, std::uint8_t id,
                  const Eigen::Matrix3d& body_R) {
  Primitive p;
  p.shape = Shape::Capsule;
  p.a = a;
  p.b = b;
  p.radius = r;
  p.material = mat;
  p.object_id = id;
  p.R = body_R;
  return p;
}

Primitive obb(const Eigen::Vector3d& c, const Eigen::Vector3d& half, const Eigen::Matrix3d& R, int mat,
              std::uint8_t id, int top = -1) {
  Primitive p;
  p.shape = Shape::Obb;
  p.a = c;
  p.b = half;
  p.R = R;
  p.material = mat;
  p.top_material = top;
  p.object_id = id;
  return p;
}

Primitive sphere(const Eigen::Vector3d& c, double r, int mat, std::uint8_t id, const Eigen::Matrix3d& R) {
  Primitive p;
  p.shape = Shape::Sphere;
  p.a = c;
  p.radius = r;
  p.material = mat;
  p.object_id = id;
  p.R = R;
  return p;
}

Eigen::Matrix3d yaw_frame(const Eigen::Vector2d& heading) {
  // Columns: right, down, forward (right-handed, y down like the camera).
  const Eigen::Vector3d z(heading.x(), 0, heading.y()), y(0, 1, 0);
  Eigen::Matrix3d R;
  R.col(0) = y.cross(z);
  R.col(1) = y;
  R.col(2) = z;
  return R;
}

}  // namespace

void PersonScript::state_at(double t, Eigen::Vector2d& pos, Eigen::Vector2d& heading, double& phase) const {
  const double s = start_offset + speed * t;
  pos = ping_pong(waypoints, s, heading);
  if (heading.squaredNorm() < 0.5) heading = Eigen::Vector2d(0, 1);
  const double stride = 0.78 * height;  // two steps
  phase = 2 * M_PI * s / stride;
}

void person_primitives(const PersonScript& p, double t, double floor_y, std::vector<Primitive>& out) {
  Eigen::Vector2d pos, heading;
  double phase;
  p.state_at(t, pos, heading, phase);
  const double H = p.height;
  const Eigen::Matrix3d R = yaw_frame(heading);
  const Eigen::Vector3d base(pos.x(), floor_y, pos.y());
  auto W = [&](double x, double y, double z) { return Eigen::Vector3d(base + R * Eigen::Vector3d(x, y, z)); };
  const std::uint8_t id = p.id;

  const double bob = 0.012 * H * std::abs(std::cos(phase));  // pelvis dips between steps
  const double hip_y = -0.53 * H + bob;
  const double shoulder_y = -0.815 * H + bob;
  const double thigh = 0.245 * H, shin = 0.25 * H;
  for (int side = 0; side < 2; ++side) {
    const double sgn = side == 0 ? -1.0 : 1.0;  // left, right
    const double ph = phase + side * M_PI;
    const double swing = 0.42 * std::sin(ph);                      // hip flexion
    const double knee = 0.12 + 0.6 * std::max(0.0, std::cos(ph));  // knee bends while the leg swings forward
    const Eigen::Vector3d hip(sgn * 0.095, hip_y, 0);
    const Eigen::Vector3d kn = hip + thigh * Eigen::Vector3d(0, std::cos(swing), std::sin(swing));
    const Eigen::Vector3d an = kn + shin * Eigen::Vector3d(0, std::cos(swing - knee), std::sin(swing - knee));
    out.push_back(capsule(W(hip.x(), hip.y(), hip.z()), W(kn.x(), kn.y(), kn.z()), 0.075, p.trousers, id, R));
    out.push_back(capsule(W(kn.x(), kn.y(), kn.z()), W(an.x(), an.y(), an.z()), 0.055, p.trousers, id, R));
    out.push_back(obb(W(an.x(), an.y() + 0.02, an.z() + 0.05), {0.05, 0.035, 0.12}, R, p.shoes, id));
    // Arms swing opposite to the leg on the same side.
    const double arm = -0.38 * std::sin(ph);
    const double elbow = 0.25 + 0.25 * std::max(0.0, -std::sin(ph));
    const Eigen::Vector3d sh(sgn * 0.21, shoulder_y + 0.04, 0);
    const Eigen::Vector3d el = sh + 0.186 * H * Eigen::Vector3d(sgn * 0.08, std::cos(arm), std::sin(arm));
    const Eigen::Vector3d wr =
        el + 0.165 * H * Eigen::Vector3d(sgn * 0.05, std::cos(arm + elbow), std::sin(arm + elbow));
    out.push_back(capsule(W(sh.x(), sh.y(), sh.z()), W(el.x(), el.y(), el.z()), 0.05, p.shirt, id, R));
    out.push_back(capsule(W(el.x(), el.y(), el.z()), W(wr.x(), wr.y(), wr.z()), 0.042, p.skin, id, R));
  }
  // Pelvis and torso (slight forward lean), neck, head with hair.
  out.push_back(obb(W(0, hip_y - 0.03, 0), {0.17, 0.08, 0.11}, R, p.trousers, id));
  const double torso_h = (hip_y - 0.08) - shoulder_y;
  Eigen::Matrix3d lean = R * Eigen::AngleAxisd(-0.05, Eigen::Vector3d::UnitX()).toRotationMatrix();
  out.push_back(obb(W(0, shoulder_y + torso_h / 2, 0.01), {0.19, torso_h / 2, 0.115}, lean, p.shirt, id));
  const double r_head = 0.062 * H;
  const Eigen::Vector3d head = W(0, -H + r_head + bob, 0.03);
  out.push_back(capsule(W(0, shoulder_y, 0.01), head, 0.05, p.skin, id, R));
  out.push_back(sphere(head, r_head, p.skin, id, R));
  out.push_back(sphere(head + R * Eigen::Vector3d(0, -0.015, -0.025), r_head * 0.98, p.hair, id, R));
}

bool ObjectScript::pose_at(double t, Eigen::Isometry3d& pose) const {
  pose.setIdentity();
  switch (kind) {
    case Kind::CarriedBox: {
      Eigen::Vector3d dir = Eigen::Vector3d::Zero();
      Eigen::Vector3d p = ping_pong(waypoints, speed * t + phase[0], dir);
      p.y() += 0.03 * std::sin(2 * M_PI * 1.8 * t);  // steps of the carrier
      const double yaw = std::atan2(dir.x(), dir.z()) + 0.3 * std::sin(0.5 * t + phase[1]);
      pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix() *
                      Eigen::AngleAxisd(0.08 * std::sin(1.3 * t), Eigen::Vector3d::UnitZ()).toRotationMatrix();
      pose.translation() = p;
      return true;
    }
    case Kind::Balloon: {
      // waypoints[0] = centre of the drift, [1] = forward, [2] = right (unit vectors).
      const Eigen::Vector3d& c = waypoints[0];
      const Eigen::Vector3d& f = waypoints[1];
      const Eigen::Vector3d& r = waypoints[2];
      pose.translation() = c + (0.45 * std::sin(0.23 * t + phase[0])) * f + (1.5 * std::sin(0.35 * t + phase[1])) * r +
                           Eigen::Vector3d(0, 0.22 * std::sin(1.1 * t + phase[2]), 0);
      pose.linear() = Eigen::AngleAxisd(0.4 * t, Eigen::Vector3d::UnitY()).toRotationMatrix();
      return true;
    }
    case Kind::ObstructingBox: {
      for (const auto& e : episodes) {
        if (t < e.start || t > e.start + e.length) continue;
        const double u = (t - e.start) / e.length;
        // Enter from the left (first quarter), stay in front while swaying, leave to the right.
        double lat;
        if (u < 0.25) {
          lat = -1.4 * (1.0 - u / 0.25);
        } else if (u > 0.75) {
          lat = 1.4 * (u - 0.75) / 0.25;
        } else {
          lat = 0.15 * std::sin(2 * M_PI * (u - 0.25) * 1.5);
        }
        // distance = to the near face; the centre is half a box further.
        const double dist = distance + 0.1 * std::sin(2 * M_PI * u) + size / 2;
        pose.translation() = e.cam_pos + dist * e.forward + lat * e.right + Eigen::Vector3d(0, 0.05, 0);
        pose.linear() = Eigen::AngleAxisd(std::atan2(e.forward.x(), e.forward.z()) + 0.15 * std::sin(3 * u),
                                          Eigen::Vector3d::UnitY())
                            .toRotationMatrix();
        return true;
      }
      return false;
    }
    case Kind::LargeBox:
      for (const auto& e : large_episodes)
        if (e.active(t)) {
          pose = e.pose_at(t);
          return true;
        }
      return false;
  }
  return false;
}

double ObjectScript::size_at(double t) const {
  if (kind == Kind::LargeBox)
    for (const auto& e : large_episodes)
      if (e.active(t)) return e.size;
  return size;
}

namespace {

// Random draws for one mover, laid out in the anchor's frame (forward, right) on the floor.
class MoverRng {
 public:
  MoverRng(std::uint64_t seed, const ViewAnchor& anchor)
      : rng_(seed), c_(anchor.center.x(), anchor.center.z()), f_(anchor.forward.x(), anchor.forward.z()),
        r_(anchor.right.x(), anchor.right.z()) {}
  double uni(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  std::uint64_t next() { return rng_(); }
  /// Floor point fwd metres ahead of and lat metres right of the anchor, jittered by up to 25 cm.
  Eigen::Vector2d at(double fwd, double lat) { return c_ + (fwd + uni(-0.25, 0.25)) * f_ + (lat + uni(-0.25, 0.25)) * r_; }
  Eigen::Vector2d ahead(double fwd) const { return c_ + fwd * f_; }

 private:
  std::mt19937_64 rng_;
  Eigen::Vector2d c_, f_, r_;
};

// Stream numbers of the mover groups (stable: changing one changes that mover only).
enum Stream : std::uint64_t { kPeopleCount = 1, kCarriedBox = 2, kBalloon = 3, kObstructingBox = 4, kLargeBox = 5, kFirstPerson = 10 };

PersonScript plan_person(std::size_t i, const ViewAnchor& anchor, std::uint64_t seed) {
  MoverRng g(mix_seed(seed, kFirstPerson + i), anchor);
  PersonScript p;
  p.id = static_cast<std::uint8_t>(kFirstPersonId + i);
  p.height = g.uni(1.6, 1.9);
  p.speed = g.uni(0.85, 1.4);
  switch (i) {
    case 0: p.waypoints = {g.at(2.3, -2.7), g.at(2.6, 2.7)}; break;                  // across the view
    case 1: p.waypoints = {g.at(4.0, 0.7), g.at(1.3, -0.2)}; break;                  // toward / away from the camera
    default: p.waypoints = {g.at(3.6, 2.3), g.at(1.7, -1.2), g.at(3.1, -2.6)}; break;  // diagonal
  }
  p.start_offset = g.uni(0.0, 3.0);
  p.look_seed = g.next();
  return p;
}

ObjectScript plan_carried_box(const ViewAnchor& anchor, double floor_y, std::uint64_t seed) {
  MoverRng g(mix_seed(seed, kCarriedBox), anchor);
  ObjectScript o;
  o.kind = ObjectScript::Kind::CarriedBox;
  o.size = g.uni(0.38, 0.45);
  o.speed = g.uni(0.7, 1.1);
  const double hand_y = floor_y - g.uni(0.95, 1.1);
  for (const auto& p : {g.at(1.8, -2.2), g.at(2.2, 0.0), g.at(2.6, 2.2)}) o.waypoints.emplace_back(p.x(), hand_y, p.y());
  o.phase[0] = g.uni(0, 2);
  o.phase[1] = g.uni(0, 6);
  o.look_seed = g.next();
  return o;
}

ObjectScript plan_balloon(const ViewAnchor& anchor, double floor_y, std::uint64_t seed) {
  MoverRng g(mix_seed(seed, kBalloon), anchor);
  ObjectScript o;
  o.kind = ObjectScript::Kind::Balloon;
  o.size = g.uni(0.32, 0.38);
  const Eigen::Vector2d cc = g.ahead(g.uni(2.0, 2.6));
  o.waypoints = {Eigen::Vector3d(cc.x(), floor_y - g.uni(1.3, 1.6), cc.y()), anchor.forward, anchor.right};
  for (double& ph : o.phase) ph = g.uni(0, 2 * M_PI);
  o.look_seed = g.next();
  return o;
}

ObjectScript plan_obstructing_box(const ViewAnchor& anchor, double duration, const Movers::PoseAt& pose_at,
                                  std::uint64_t seed) {
  MoverRng g(mix_seed(seed, kObstructingBox), anchor);
  ObjectScript o;
  o.kind = ObjectScript::Kind::ObstructingBox;
  o.size = g.uni(0.6, 0.7);
  o.distance = g.uni(0.85, 1.0);
  const double len = std::min(6.0, 0.7 * duration);
  for (double s = std::min(1.5, 0.15 * duration); s + len <= duration + 1e-9; s += 10.0) {
    ObjectScript::Episode e;
    e.start = s;
    e.length = len;
    const Eigen::Isometry3d T = pose_at(s + len / 2);
    e.cam_pos = T.translation();
    Eigen::Vector3d fw = T.rotation().col(2);
    fw.y() = 0;
    e.forward = fw.norm() > 1e-6 ? fw.normalized() : Eigen::Vector3d::UnitZ();
    e.right = Eigen::Vector3d::UnitY().cross(e.forward);
    o.episodes.push_back(e);
  }
  o.look_seed = g.next();
  return o;
}

ObjectScript plan_large_box(double duration, const Movers::PoseAt& pose_at, std::uint64_t seed) {
  std::mt19937_64 rng(mix_seed(seed, kLargeBox));
  ObjectScript o;
  o.kind = ObjectScript::Kind::LargeBox;
  o.size = 1.0;  // texture scale; each episode has its own edge
  o.large_episodes = plan_large_box_episodes(duration, pose_at, rng);
  o.look_seed = rng();
  return o;
}

}  // namespace

Movers Movers::plan_all(const ViewAnchor& anchor, double floor_y, double duration, const PoseAt& pose_at,
                        std::uint64_t seed) {
  Movers m;
  m.floor_y_ = floor_y;
  for (std::size_t i = 0; i < 3; ++i) m.people_.push_back(plan_person(i, anchor, seed));
  std::mt19937_64 count_rng(mix_seed(seed, kPeopleCount));
  m.walking_people_ = std::uniform_real_distribution<double>(0, 1)(count_rng) < 0.5 ? 2 : 3;
  m.objects_ = {plan_carried_box(anchor, floor_y, seed), plan_balloon(anchor, floor_y, seed),
                plan_obstructing_box(anchor, duration, pose_at, seed), plan_large_box(duration, pose_at, seed)};
  return m;
}

Movers Movers::select(const std::string& scenario) const {
  Movers m;
  m.floor_y_ = floor_y_;
  const bool two_people = scenario == "mixed" || scenario == "large_box_people";
  const std::size_t n_people = scenario == "walking" ? walking_people_ : two_people ? 2 : 0;
  m.people_.assign(people_.begin(), people_.begin() + static_cast<std::ptrdiff_t>(std::min(n_people, people_.size())));
  m.walking_people_ = m.people_.size();
  auto wanted = [&](ObjectScript::Kind k) {
    switch (k) {
      case ObjectScript::Kind::CarriedBox: return scenario == "unknown_box" || scenario == "mixed";
      case ObjectScript::Kind::Balloon: return scenario == "balloon" || scenario == "mixed";
      case ObjectScript::Kind::ObstructingBox: return scenario == "obstructing_box";
      case ObjectScript::Kind::LargeBox: return scenario == "large_box" || scenario == "large_box_people";
    }
    return false;
  };
  std::uint8_t next_id = kFirstObjectId;
  for (const auto& o : objects_)
    if (wanted(o.kind)) {
      m.objects_.push_back(o);
      m.objects_.back().id = next_id++;
    }
  return m;
}

Movers Movers::script(const std::string& scenario, const ViewAnchor& anchor, double floor_y, double duration,
                      const PoseAt& pose_at, std::uint64_t seed) {
  return plan_all(anchor, floor_y, duration, pose_at, seed).select(scenario);
}

std::vector<KeepOut> Movers::keep_outs() const {
  std::vector<KeepOut> out;
  for (const auto& p : people_)
    for (std::size_t i = 1; i < p.waypoints.size(); ++i) {
      const Eigen::Vector2d a = p.waypoints[i - 1], b = p.waypoints[i];
      const int n = static_cast<int>((b - a).norm() / 0.3) + 1;
      for (int k = 0; k <= n; ++k) out.push_back({a + (b - a) * k / n, 0.55});
    }
  for (const auto& o : objects_)
    if (o.kind == ObjectScript::Kind::CarriedBox)
      for (std::size_t i = 1; i < o.waypoints.size(); ++i) {
        const Eigen::Vector2d a(o.waypoints[i - 1].x(), o.waypoints[i - 1].z()), b(o.waypoints[i].x(), o.waypoints[i].z());
        const int n = static_cast<int>((b - a).norm() / 0.3) + 1;
        for (int k = 0; k <= n; ++k) out.push_back({a + (b - a) * k / n, 0.5});
      }
  return out;
}

std::vector<Eigen::Vector3d> Movers::extent_points() const {
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : people_)
    for (const auto& w : p.waypoints) out.emplace_back(w.x(), floor_y_, w.y());
  for (const auto& o : objects_)
    if (o.kind == ObjectScript::Kind::CarriedBox)
      for (const auto& w : o.waypoints) out.push_back(w);
  return out;
}

void Movers::add_materials(Scene& scene) {
  const cv::Vec3b skins[] = {{150, 180, 225}, {110, 145, 195}, {70, 100, 150}, {130, 165, 210}};
  for (auto& p : people_) {
    std::mt19937_64 rng(p.look_seed);
    auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
    auto col = [&](int lo, int hi) {
      return cv::Vec3b(static_cast<uchar>(uni(lo, hi)), static_cast<uchar>(uni(lo, hi)), static_cast<uchar>(uni(lo, hi)));
    };
    p.shirt_color = col(30, 230);
    p.shirt_pattern = static_cast<int>(uni(0, 2.99));
    p.shirt = scene.add_material(scene.add_texture(texgen::fabric(256, p.shirt_color, p.shirt_pattern, rng())), 0.002, "shirt");
    const cv::Vec3b trousers = uni(0, 1) < 0.6 ? cv::Vec3b(130, 80, 40) : col(30, 90);
    p.trousers = scene.add_material(scene.add_texture(texgen::fabric(256, trousers, 0, rng())), 0.0015, "trousers");
    p.skin = scene.add_material(scene.add_texture(texgen::plaster(128, skins[rng() % 4], rng())), 0.002, "skin");
    p.hair = scene.add_material(scene.add_texture(texgen::fabric(128, col(15, 60), 0, rng())), 0.001, "hair");
    p.shoes = scene.add_material(scene.add_texture(texgen::plain(64, col(10, 50), rng())), 0.005, "shoes");
  }
  for (auto& o : objects_) {
    std::mt19937_64 rng(o.look_seed);
    if (o.kind == ObjectScript::Kind::Balloon) {
      cv::Mat tex = texgen::fabric(256, cv::Vec3b(40, 40, 200), 0, rng());
      cv::circle(tex, cv::Point(128, 128), 50, cv::Scalar(240, 240, 240), -1, cv::LINE_AA);  // printed logo
      cv::circle(tex, cv::Point(128, 128), 25, cv::Scalar(40, 160, 240), -1, cv::LINE_AA);
      o.material = scene.add_material(scene.add_texture(tex), M_PI * o.size / 256, "balloon");
    } else {
      o.material = scene.add_material(scene.add_texture(texgen::cardboard(256, rng())), o.size / 256, "cardboard");
    }
  }
}

void Movers::primitives_at(double t, std::vector<Primitive>& out) const {
  for (const auto& p : people_) person_primitives(p, t, floor_y_, out);
  for (const auto& o : objects_) {
    Eigen::Isometry3d T;
    if (!o.pose_at(t, T)) continue;
    if (o.kind == ObjectScript::Kind::Balloon) {
      out.push_back(sphere(T.translation(), o.size / 2, o.material, o.id, T.rotation()));
    } else {
      const double h = o.size_at(t) / 2;
      out.push_back(obb(T.translation(), {h, h * 0.85, h}, T.rotation(), o.material, o.id));
    }
  }
}

nlohmann::json Movers::describe() const {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& p : people_) {
    nlohmann::json wp = nlohmann::json::array();
    for (const auto& w : p.waypoints) wp.push_back({w.x(), w.y()});
    j.push_back({{"type", "person"}, {"label", "person"}, {"id", p.id}, {"height_m", p.height},
                 {"speed_mps", p.speed}, {"waypoints_xz", wp}, {"start_offset_m", p.start_offset},
                 {"shirt_pattern", p.shirt_pattern}});
  }
  for (const auto& o : objects_) {
    nlohmann::json e{{"id", o.id}, {"size_m", o.size}, {"label", nullptr}};
    switch (o.kind) {
      case ObjectScript::Kind::CarriedBox: {
        e["type"] = "carried_box";
        e["speed_mps"] = o.speed;
        nlohmann::json wp = nlohmann::json::array();
        for (const auto& w : o.waypoints) wp.push_back({w.x(), w.y(), w.z()});
        e["waypoints_xyz"] = wp;
        break;
      }
      case ObjectScript::Kind::Balloon:
        e["type"] = "balloon";
        e["drift_centre"] = {o.waypoints[0].x(), o.waypoints[0].y(), o.waypoints[0].z()};
        break;
      case ObjectScript::Kind::ObstructingBox: {
        e["type"] = "obstructing_box";
        e["distance_m"] = o.distance;
        nlohmann::json eps = nlohmann::json::array();
        for (const auto& ep : o.episodes) eps.push_back({{"start_s", ep.start}, {"length_s", ep.length}});
        e["episodes"] = eps;
        break;
      }
      case ObjectScript::Kind::LargeBox: {
        e["type"] = "large_box";
        nlohmann::json eps = nlohmann::json::array();
        for (const auto& ep : o.large_episodes) eps.push_back(ep.describe());
        e["episodes"] = eps;
        break;
      }
    }
    j.push_back(e);
  }
  return j;
}

}  // namespace varslam::synth
