#pragma once
// Follows a dense map's surface as it grows, for a live view (the browser viewer's layer, the ROS node's cloud):
// each update() reads only the blocks the map changed since the previous one, from a shared copy of the map (no lock
// held while reading), and keeps their surface points (the mesh's vertices) thinned to one point per cube of cell_voxels^3 voxels.
// Points are grouped into regions (cubes of kRegionBlocks^3 blocks) so a view resends only the regions that changed.
// One thread uses a tracker at a time.
#include <Eigen/Core>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "dense/tsdf_volume.hpp"

namespace varslam::dense {

class DenseMapper;

class SurfaceTracker {
 public:
  static constexpr int kRegionBlocks = 4;            // a region: 4^3 blocks (64 cm at 2-cm voxels)
  using RegionKey = TsdfVolume::BlockKey;

  /// cell_voxels: 1, 2, 4 or 8 (std::invalid_argument otherwise).
  SurfaceTracker(int cell_voxels, double voxel_size);

  /// Reads what changed in `map` since the last call. Returns the regions whose points changed (sorted; a region
  /// may have no points left).
  std::vector<RegionKey> update(const DenseMapper& map);
  std::vector<RegionKey> update(const TsdfVolume& volume);

  std::vector<SurfacePoint> region_points(RegionKey region) const;
  std::vector<SurfacePoint> all_points() const;  // sorted by block: the same map gives the same list
  std::size_t point_count() const;
  static Eigen::Vector3i region_index(RegionKey region) { return TsdfVolume::block_coords(region); }
  double region_size() const { return voxel_size_ * TsdfVolume::kBlock * kRegionBlocks; }
  double cell_size() const { return voxel_size_ * cell_; }

 private:
  RegionKey region_of(TsdfVolume::BlockKey block) const;
  std::vector<SurfacePoint> thin(TsdfVolume::BlockKey block, const std::vector<SurfacePoint>& points) const;

  int cell_;
  double voxel_size_;
  std::uint64_t epoch_ = ~std::uint64_t{0}, stamp_ = 0;
  std::unordered_map<TsdfVolume::BlockKey, std::vector<SurfacePoint>> blocks_;  // the non-empty ones
};

}  // namespace varslam::dense
