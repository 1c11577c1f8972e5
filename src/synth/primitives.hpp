#pragma once
// Geometric primitives of the synthetic scene and their ray intersections (own code: slab test for boxes,
// quadratic for spheres and capsules). Rays use a unit direction; t is the distance along the ray.
#include <Eigen/Core>
#include <cstdint>

namespace varslam::synth {

enum class Shape : std::uint8_t { Aabb, Obb, Sphere, Capsule };

/// Object ids in the id buffer: 0 = static scene, 1..9 = people, 10.. = unknown movers.
constexpr std::uint8_t kStaticId = 0;
constexpr std::uint8_t kFirstPersonId = 1;
constexpr std::uint8_t kFirstObjectId = 10;

struct Primitive {
  Shape shape = Shape::Aabb;
  std::uint8_t object_id = kStaticId;
  int material = 0;
  int top_material = -1;  // Aabb/Obb: material of the faces along local y (table tops); -1 = same
  // Aabb: a = min, b = max. Obb: a = centre, b = half extents. Sphere: a = centre. Capsule: segment a-b.
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double radius = 0.0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // local axes (columns) in world, for Obb and texturing

  /// World-space bounding box (for screen-space culling).
  void bounds(Eigen::Vector3d& lo, Eigen::Vector3d& hi) const;
};

struct Hit {
  double t = 0.0;
  Eigen::Vector3d n = Eigen::Vector3d::Zero();  // unit normal (not yet flipped toward the viewer)
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // surface coordinates in metres
  int material = 0;
  std::uint8_t object_id = kStaticId;
};

/// Nearest hit with t in (t_min, t_max); on success fills hit (incl. normal and uv) and returns true.
bool intersect(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max,
               Hit& hit);

/// Where a ray from inside the box [lo, hi] leaves it (walls, floor, ceiling of the room).
/// axis receives 0/1/2 and side 0 (lo) or 1 (hi) of the face that was hit.
double exit_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Vector3d& o,
                const Eigen::Vector3d& d, int& axis, int& side);

}  // namespace varslam::synth
