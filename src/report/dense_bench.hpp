#pragma once
// The dense map's benchmark on the synthetic generator, which knows the static geometry and every mover's volume:
//  - accuracy: distance from each mesh vertex to the nearest static surface (room faces, furniture);
//  - completeness: share of the static surface the cameras saw (points of the static scene rendered without movers
//    from the ground-truth poses, within the dense map's range) that has a mesh vertex within `within_m`;
//  - ghosts: the movers' swept volume (voxels inside a mover at some frame, seen from some camera, more than two
//    voxels from any static surface), and how much of it the map holds as occupied (its occupancy voxels) or meshed.
// The map is compared in the SLAM world frame, which is the ground truth's (both start at the first camera), without
// alignment: trajectory error is part of the accuracy.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/camera.hpp"
#include "dense/tsdf_volume.hpp"
#include "synth/world.hpp"

namespace varslam::report {

struct DenseTruthOptions {
  double voxel_size = 0.02;
  double max_range = 4.0;   // reference points as far as the map fuses
  int frame_step = 10;      // frames between reference renderings and visibility tests
  int pixel_step = 4;
  double within_m = 0.02;
};

struct DenseScores {
  std::size_t vertices = 0, reference_points = 0;
  double accuracy_mean_cm = 0, accuracy_median_cm = 0, accuracy_within = 0;  // share of vertices within within_m
  double completeness_median_cm = 0, completeness_within = 0;  // distances capped at 5 cm
  std::size_t swept_voxels = 0, ghost_voxels = 0, ghost_vertices = 0;
  double ghost_share = 0;         // ghost_voxels / swept_voxels
  double ghost_vertex_share = 0;  // of all vertices
  nlohmann::json to_json() const;
};

/// Distance (m) from p to the nearest static surface of the scene (room faces and furniture).
double distance_to_static(const synth::Scene& scene, const Eigen::Vector3d& p);
/// True when p lies inside the primitive.
bool inside(const synth::Primitive& prim, const Eigen::Vector3d& p);

/// For each point of `from`, the distance (m) to the nearest vertex of `to`, capped at 5 cm.
std::vector<double> nearest_vertex_distances(const std::vector<Eigen::Vector3f>& from,
                                             const std::vector<Eigen::Vector3f>& to);

/// Two meshes of one scene compared vertex to vertex (a SLAM mesh against one fused from ground-truth poses).
struct MeshComparison {
  double accuracy_mean_cm = 0, accuracy_median_cm = 0, accuracy_within = 0;  // mesh -> reference, capped at 5 cm
  double completeness_within = 0;                                            // reference -> mesh
  std::size_t vertices = 0, reference_vertices = 0;
  nlohmann::json to_json() const;
};
MeshComparison compare_meshes(const std::vector<Eigen::Vector3f>& mesh, const std::vector<Eigen::Vector3f>& reference,
                              double within_m = 0.02);

DenseScores score_dense_map(const synth::World& world, const PinholeCamera& camera, const dense::Mesh& mesh,
                            const std::vector<dense::OccupancyVoxel>& occupancy, const DenseTruthOptions& opt);

}  // namespace varslam::report
