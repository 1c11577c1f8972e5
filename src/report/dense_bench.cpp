#include "report/dense_bench.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "synth/renderer.hpp"

namespace varslam::report {

namespace {

std::uint64_t cell_key(const Eigen::Vector3i& c) {
  constexpr int kBias = 1 << 20;
  return (static_cast<std::uint64_t>(c.x() + kBias) << 42) | (static_cast<std::uint64_t>(c.y() + kBias) << 21) |
         static_cast<std::uint64_t>(c.z() + kBias);
}

Eigen::Vector3i cell_of(const Eigen::Vector3d& p, double size) {
  return {static_cast<int>(std::floor(p.x() / size)), static_cast<int>(std::floor(p.y() / size)),
          static_cast<int>(std::floor(p.z() / size))};
}

// Distance from p to the surface of the box [lo, hi] (inside or out).
double box_surface_distance(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Vector3d& p) {
  const Eigen::Vector3d out = (lo - p).cwiseMax(p - hi).cwiseMax(Eigen::Vector3d::Zero());
  if (out.squaredNorm() > 0) return out.norm();
  return std::min((p - lo).minCoeff(), (hi - p).minCoeff());
}

double segment_distance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& p) {
  const Eigen::Vector3d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double primitive_distance(const synth::Primitive& q, const Eigen::Vector3d& p) {
  switch (q.shape) {
    case synth::Shape::Aabb: return box_surface_distance(q.a, q.b, p);
    case synth::Shape::Obb: {
      const Eigen::Vector3d l = q.R.transpose() * (p - q.a);
      return box_surface_distance(-q.b, q.b, l);
    }
    case synth::Shape::Sphere: return std::abs((p - q.a).norm() - q.radius);
    case synth::Shape::Capsule: return std::abs(segment_distance(q.a, q.b, p) - q.radius);
  }
  return 1e9;
}

// Nearest-vertex queries on a hash grid of 5-cm cells (distances beyond 5 cm are reported as 5 cm).
class VertexGrid {
 public:
  static constexpr double kCell = 0.05;
  explicit VertexGrid(const std::vector<Eigen::Vector3f>& v) : v_(v) {
    for (std::size_t i = 0; i < v.size(); ++i) cells_[cell_key(cell_of(v[i].cast<double>(), kCell))].push_back(i);
  }
  double nearest(const Eigen::Vector3d& p) const {
    const Eigen::Vector3i c = cell_of(p, kCell);
    double best = kCell * kCell;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = cells_.find(cell_key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (const std::size_t i : it->second) best = std::min(best, (v_[i].cast<double>() - p).squaredNorm());
        }
    return std::sqrt(best);
  }

 private:
  const std::vector<Eigen::Vector3f>& v_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

bool inside(const synth::Primitive& q, const Eigen::Vector3d& p) {
  switch (q.shape) {
    case synth::Shape::Aabb: return (p.array() >= q.a.array()).all() && (p.array() <= q.b.array()).all();
    case synth::Shape::Obb: {
      const Eigen::Vector3d l = q.R.transpose() * (p - q.a);
      return (l.cwiseAbs().array() <= q.b.array()).all();
    }
    case synth::Shape::Sphere: return (p - q.a).norm() <= q.radius;
    case synth::Shape::Capsule: return segment_distance(q.a, q.b, p) <= q.radius;
  }
  return false;
}

double distance_to_static(const synth::Scene& scene, const Eigen::Vector3d& p) {
  double d = box_surface_distance(scene.room_lo, scene.room_hi, p);
  for (const synth::Primitive& q : scene.statics) d = std::min(d, primitive_distance(q, p));
  return d;
}

nlohmann::json DenseScores::to_json() const {
  return {{"vertices", vertices},
          {"reference_points", reference_points},
          {"accuracy_mean_cm", accuracy_mean_cm},
          {"accuracy_median_cm", accuracy_median_cm},
          {"accuracy_within_2cm", accuracy_within},
          {"completeness_median_cm", completeness_median_cm},
          {"completeness_within_2cm", completeness_within},
          {"swept_voxels", swept_voxels},
          {"ghost_voxels", ghost_voxels},
          {"ghost_share", ghost_share},
          {"ghost_vertices", ghost_vertices},
          {"ghost_vertex_share", ghost_vertex_share}};
}

std::vector<double> nearest_vertex_distances(const std::vector<Eigen::Vector3f>& from,
                                             const std::vector<Eigen::Vector3f>& to) {
  const VertexGrid grid(to);
  std::vector<double> d(from.size());
  for (std::size_t i = 0; i < from.size(); ++i) d[i] = grid.nearest(from[i].cast<double>());
  return d;
}

nlohmann::json MeshComparison::to_json() const {
  return {{"vertices", vertices},
          {"reference_vertices", reference_vertices},
          {"accuracy_mean_cm", accuracy_mean_cm},
          {"accuracy_median_cm", accuracy_median_cm},
          {"accuracy_within_2cm", accuracy_within},
          {"completeness_within_2cm", completeness_within}};
}

MeshComparison compare_meshes(const std::vector<Eigen::Vector3f>& mesh, const std::vector<Eigen::Vector3f>& reference,
                              double within_m) {
  MeshComparison c;
  c.vertices = mesh.size();
  c.reference_vertices = reference.size();
  const std::vector<double> a = nearest_vertex_distances(mesh, reference);
  const std::vector<double> b = nearest_vertex_distances(reference, mesh);
  double sum = 0;
  std::size_t in = 0;
  for (const double x : a) {
    sum += x;
    in += x <= within_m ? 1 : 0;
  }
  if (!a.empty()) {
    c.accuracy_mean_cm = 100.0 * sum / static_cast<double>(a.size());
    c.accuracy_median_cm = 100.0 * median(a);
    c.accuracy_within = static_cast<double>(in) / static_cast<double>(a.size());
  }
  std::size_t cov = 0;
  for (const double x : b) cov += x <= within_m ? 1 : 0;
  if (!b.empty()) c.completeness_within = static_cast<double>(cov) / static_cast<double>(b.size());
  return c;
}

DenseScores score_dense_map(const synth::World& world, const PinholeCamera& camera, const dense::Mesh& mesh,
                            const std::vector<dense::OccupancyVoxel>& occupancy, const DenseTruthOptions& opt) {
  DenseScores s;
  s.vertices = mesh.vertices.size();
  const double vs = opt.voxel_size;

  // Accuracy: every vertex against the static geometry.
  std::vector<double> acc(mesh.vertices.size());
  std::size_t within = 0;
  double sum = 0;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    acc[i] = distance_to_static(world.scene, mesh.vertices[i].cast<double>());
    sum += acc[i];
    within += acc[i] <= opt.within_m ? 1 : 0;
  }
  if (!acc.empty()) {
    s.accuracy_mean_cm = 100.0 * sum / static_cast<double>(acc.size());
    s.accuracy_median_cm = 100.0 * median(acc);
    s.accuracy_within = static_cast<double>(within) / static_cast<double>(acc.size());
  }

  // Completeness: the static scene as the cameras saw it, within range (rendered without movers).
  const synth::Renderer renderer(camera);
  synth::RenderOutput r;
  std::unordered_set<std::uint64_t> ref_cells;
  std::vector<Eigen::Vector3d> ref;
  const std::size_t step = static_cast<std::size_t>(std::max(1, opt.frame_step));
  for (std::size_t f = 0; f < world.poses.size(); f += step) {
    renderer.render(world.scene, {}, world.poses[f], r);
    for (int v = 0; v < r.depth.rows; v += opt.pixel_step)
      for (int u = 0; u < r.depth.cols; u += opt.pixel_step) {
        const double z = r.depth(v, u);
        if (!(z > 0.2 && z <= opt.max_range)) continue;
        const Eigen::Vector3d p = world.poses[f] * camera.unproject(u, v, z);
        if (ref_cells.insert(cell_key(cell_of(p, 0.01))).second) ref.push_back(p);
      }
  }
  s.reference_points = ref.size();
  const VertexGrid grid(mesh.vertices);
  std::vector<double> comp(ref.size());
  std::size_t covered = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    comp[i] = grid.nearest(ref[i]);
    covered += comp[i] <= opt.within_m ? 1 : 0;
  }
  if (!ref.empty()) {
    s.completeness_median_cm = 100.0 * median(comp);
    s.completeness_within = static_cast<double>(covered) / static_cast<double>(ref.size());
  }

  // The movers' swept volume: voxels inside a mover at some frame, in view of some camera within range, more than
  // two voxels from static geometry (a foot on the floor is not a ghost).
  std::unordered_set<std::uint64_t> swept;
  std::vector<synth::Primitive> prims;
  const double fps = world.stamps.size() > 1 ? 1.0 / (world.stamps[1] - world.stamps[0]) : 30.0;
  for (std::size_t f = 0; f < world.poses.size(); ++f) {
    prims.clear();
    world.movers.primitives_at(static_cast<double>(f) / fps, prims);
    for (const synth::Primitive& q : prims) {
      Eigen::Vector3d lo, hi;
      q.bounds(lo, hi);
      const Eigen::Vector3i a = cell_of(lo, vs), b = cell_of(hi, vs);
      for (int z = a.z(); z <= b.z(); ++z)
        for (int y = a.y(); y <= b.y(); ++y)
          for (int x = a.x(); x <= b.x(); ++x) {
            const Eigen::Vector3d c = (Eigen::Vector3d(x, y, z) + Eigen::Vector3d::Constant(0.5)) * vs;
            if (inside(q, c)) swept.insert(cell_key({x, y, z}));
          }
    }
  }
  std::unordered_set<std::uint64_t> counted;
  auto unkey = [](std::uint64_t k) {
    constexpr int kBias = 1 << 20;
    const auto m = (std::uint64_t{1} << 21) - 1;
    return Eigen::Vector3i(static_cast<int>((k >> 42) & m) - kBias, static_cast<int>((k >> 21) & m) - kBias,
                           static_cast<int>(k & m) - kBias);
  };
  for (const std::uint64_t k : swept) {
    const Eigen::Vector3d c = (unkey(k).cast<double>() + Eigen::Vector3d::Constant(0.5)) * vs;
    if (distance_to_static(world.scene, c) <= 2 * vs) continue;
    bool seen = false;
    for (std::size_t f = 0; f < world.poses.size() && !seen; f += step) {
      const Eigen::Vector3d pc = world.poses[f].inverse() * c;
      if (pc.z() <= 0.2 || pc.z() > opt.max_range) continue;
      const Eigen::Vector2d px = camera.project(pc);
      seen = camera.in_image(px.x(), px.y());
    }
    if (seen) counted.insert(k);
  }
  s.swept_voxels = counted.size();
  for (const dense::OccupancyVoxel& v : occupancy)
    if (v.occupied && counted.count(cell_key(cell_of(v.centre.cast<double>(), vs)))) ++s.ghost_voxels;
  for (const Eigen::Vector3f& v : mesh.vertices)
    if (counted.count(cell_key(cell_of(v.cast<double>(), vs)))) ++s.ghost_vertices;
  s.ghost_share = s.swept_voxels ? static_cast<double>(s.ghost_voxels) / static_cast<double>(s.swept_voxels) : 0.0;
  s.ghost_vertex_share = s.vertices ? static_cast<double>(s.ghost_vertices) / static_cast<double>(s.vertices) : 0.0;
  return s;
}

}  // namespace varslam::report
