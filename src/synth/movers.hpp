#pragma once
// Scripted movers: articulated walking people (with a gait) and unknown objects (carried box, obstructing box,
// balloon). Scripts are laid out relative to where the camera looks, so movers are in view much of the time.
// The movers of all scenarios are planned together (one RNG stream per mover), so the static room, which is laid
// out around every planned mover, is the same for every scenario; a scenario only selects which movers appear.
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "synth/large_box.hpp"
#include "synth/primitives.hpp"
#include "synth/scene.hpp"

namespace varslam::synth {

struct PersonScript {
  std::uint8_t id = kFirstPersonId;
  double height = 1.75, speed = 1.1;      // metres, metres per second
  std::vector<Eigen::Vector2d> waypoints;  // floor (x, z); walked back and forth
  double start_offset = 0.0;               // metres along the walk at t = 0
  int shirt = 0, trousers = 0, skin = 0, hair = 0, shoes = 0;  // materials
  cv::Vec3b shirt_color{0, 0, 0};
  int shirt_pattern = 0;
  std::uint64_t look_seed = 0;  // clothing and skin textures

  /// Floor position and unit heading (x, z) at time t; phase = gait phase in radians.
  void state_at(double t, Eigen::Vector2d& pos, Eigen::Vector2d& heading, double& phase) const;
};

struct ObjectScript {
  enum class Kind { CarriedBox, Balloon, ObstructingBox, LargeBox };
  Kind kind = Kind::CarriedBox;
  std::uint8_t id = kFirstObjectId;
  double size = 0.4;  // box edge or balloon diameter
  int material = 0;
  // CarriedBox: ping-pong between waypoints at this speed, at height y. Balloon: drift parameters.
  std::vector<Eigen::Vector3d> waypoints;
  double speed = 0.9;
  double phase[3] = {0, 0, 0};
  // ObstructingBox: per-episode anchor (camera pose at the episode's middle) and timing.
  struct Episode {
    double start = 0, length = 0;
    Eigen::Vector3d cam_pos = Eigen::Vector3d::Zero(), forward = Eigen::Vector3d::UnitZ(),
                    right = Eigen::Vector3d::UnitX();
  };
  std::vector<Episode> episodes;
  double distance = 1.1;
  // LargeBox: its episodes, each with its own size and precomputed track.
  std::vector<LargeBoxEpisode> large_episodes;
  std::uint64_t look_seed = 0;  // texture

  /// Edge length at t (a large box's size changes from episode to episode).
  double size_at(double t) const;

  /// Pose of the object at t; false when it is not in the scene (obstructing box between episodes).
  bool pose_at(double t, Eigen::Isometry3d& pose) const;
};

class Movers {
 public:
  using PoseAt = std::function<Eigen::Isometry3d(double)>;

  /// Every mover any scenario uses (three people, carried box, balloon, obstructing box, large box), each from its own RNG
  /// stream, so a mover does not depend on which others exist. pose_at(t) = camera-to-world pose at t seconds.
  static Movers plan_all(const ViewAnchor& anchor, double floor_y, double duration, const PoseAt& pose_at,
                         std::uint64_t seed);
  /// The movers of one scenario, taken from this plan (object ids renumbered from kFirstObjectId).
  Movers select(const std::string& scenario) const;
  /// plan_all(...).select(scenario).
  static Movers script(const std::string& scenario, const ViewAnchor& anchor, double floor_y, double duration,
                       const PoseAt& pose_at, std::uint64_t seed);

  /// Floor zones that furniture must leave free (walking lanes).
  std::vector<KeepOut> keep_outs() const;
  /// Points (world) the room must enclose.
  std::vector<Eigen::Vector3d> extent_points() const;
  /// Create clothing / object textures and materials in the scene (from each mover's look_seed).
  void add_materials(Scene& scene);
  /// All mover primitives at time t (seconds since the start).
  void primitives_at(double t, std::vector<Primitive>& out) const;
  nlohmann::json describe() const;

  const std::vector<PersonScript>& people() const { return people_; }
  const std::vector<ObjectScript>& objects() const { return objects_; }

 private:
  std::vector<PersonScript> people_;
  std::vector<ObjectScript> objects_;
  double floor_y_ = 0.0;
  std::size_t walking_people_ = 0;  // how many of the planned people the walking scenario shows
};

/// Body parts of one person in world coordinates (exposed for tests).
void person_primitives(const PersonScript& p, double t, double floor_y, std::vector<Primitive>& out);

}  // namespace varslam::synth
