#pragma once
// A truncated signed distance field on a sparse voxel grid (blocks of 8^3 voxels in a hash map), our own: depth
// images are fused projectively, pixels marked as movers are left out of the surface, and every depth pixel clears
// the space in front of what it sees (a voxel more than the truncation distance in front of the measured surface
// gets a "free" observation, so a mover fused once and then seen through is voted away). Every update is a plain
// weighted sum with weight 1 per observation, so a keyframe's contribution can be taken out again exactly the way it
// was put in (integrate with sign -1): a keyframe whose pose changed after Local BA or a loop is re-integrated.
//
// Voxel (i, j, k) has its centre at ((i, j, k) + 0.5) * voxel_size in the world frame (the grid of an OcTree of
// the same resolution). Not thread-safe: one thread owns a volume; share() hands out a copy other threads may read
// while the owner goes on fusing (blocks are shared until the owner writes one: copy on write).
#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <unordered_map>
#include <vector>

#include "core/camera.hpp"

namespace varslam::dense {

/// a / b rounded towards minus infinity (b > 0): the block or region holding a voxel at a negative index.
inline int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

struct TsdfConfig {
  double voxel_size = 0.02;        // metres
  double truncation_voxels = 4.0;  // the truncation distance in voxels
  // Metres along the optical axis: depth outside adds no surface; depth beyond max_range still clears the space
  // up to max_range.
  double min_range = 0.2, max_range = 4.0;
  int min_weight = 1;              // observations a voxel needs to count (mesh, occupancy)
  bool carve = true;               // free-space observations in front of the measured surface
  // A voxel seen only as free space at least this many times stays free when a surface appears in it (something
  // moved in); 0 = off.
  int keep_free_votes = 2;
  double truncation() const { return truncation_voxels * voxel_size; }
};

/// One image to fuse: depth (CV_32FC1, metres, 0 = none), optional colour (CV_8UC3, same size) and mover mask
/// (CV_8UC1, non-zero = a mover: the pixel still clears the space in front of it, but adds no surface), seen by
/// `camera` (its size = the images') from camera-to-world pose T_wc.
struct DepthView {
  cv::Mat depth, bgr, movers;
  PinholeCamera camera;
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
};

struct Voxel {
  float sdf_sum = 0;   // sum of the truncated signed distances / truncation, in [-1, 1] each
  float weight = 0;    // observations (surface and free)
  float colour_weight = 0;
  std::array<float, 3> bgr_sum{0, 0, 0};
  float sdf() const { return weight > 0 ? sdf_sum / weight : 1.0f; }
};

struct Mesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<std::uint8_t, 3>> colours;  // RGB per vertex
  std::vector<std::array<std::int32_t, 3>> triangles;
};

/// A point on the surface: the mesh vertex of one voxel cell the surface passes through, with its colour.
struct SurfacePoint {
  Eigen::Vector3f position;
  std::array<std::uint8_t, 3> rgb{};
};

/// A voxel of the occupancy grid: its centre and whether it is occupied (else observed free).
struct OccupancyVoxel {
  Eigen::Vector3f centre;
  bool occupied = false;
};

struct IntegrationStats {
  std::size_t blocks_touched = 0, voxels_updated = 0, voxels_carved = 0, voxels_kept_free = 0, pixels_used = 0,
              pixels_moving = 0;
  bool cancelled = false;
};

class TsdfVolume {
 public:
  static constexpr int kBlock = 8;
  using BlockKey = std::uint64_t;
  explicit TsdfVolume(const TsdfConfig& cfg);
  // A plain copy would share blocks both sides then write into: share() is the one way to copy.
  TsdfVolume(const TsdfVolume&) = delete;
  TsdfVolume& operator=(const TsdfVolume&) = delete;
  TsdfVolume(TsdfVolume&&) = default;
  TsdfVolume& operator=(TsdfVolume&&) = default;

  /// Fuses (sign +1) or takes out again (sign -1, the same view and pose) one view. When `cancel` becomes true the
  /// fusion stops part way (IntegrationStats::cancelled): the volume is then half updated, fit only to be cleared.
  IntegrationStats integrate(const DepthView& view, int sign = 1, const std::atomic<bool>* cancel = nullptr);
  void clear() {
    blocks_.clear();
    ++epoch_;
  }
  /// A copy as it is now, for readers on other threads: it never changes, whatever this volume fuses afterwards
  /// (the blocks it holds are copied before this volume writes into them).
  std::shared_ptr<const TsdfVolume> share();

  // Following the surface as it changes (a live view reads only what changed): every integrate() advances the
  // stamp, and each block it changed keeps the stamp of that change. clear() starts a new epoch.
  std::uint64_t stamp() const { return stamp_; }
  std::uint64_t epoch() const { return epoch_; }
  /// Blocks changed after `since`, and the blocks whose surface cells read a changed block (a cell reads the
  /// voxels at +0/+1 on each axis, so a change reaches the blocks below it too).
  std::vector<BlockKey> changed_since(std::uint64_t since) const;
  /// The surface points (extract_mesh()'s vertices) of the cells whose first corner is in block k; none when k is
  /// not allocated.
  void block_surface(BlockKey k, std::vector<SurfacePoint>& out) const;
  static Eigen::Vector3i block_coords(BlockKey k) { return unkey(k); }
  static BlockKey block_key(const Eigen::Vector3i& b) { return key(b.x(), b.y(), b.z()); }

  /// Surface (dual contouring of the zero crossings, vertex at the mean of its cell's edge crossings), vertices and
  /// triangles in a deterministic order (blocks sorted by coordinate).
  Mesh extract_mesh() const;
  /// Voxels that count (min_weight): occupied where the surface is (sdf <= 0 within two voxels of the zero
  /// crossing), free where the distance is positive. Sorted by coordinate.
  std::vector<OccupancyVoxel> occupancy() const;

  std::size_t block_count() const { return blocks_.size(); }
  std::size_t observed_voxels() const;
  const TsdfConfig& config() const { return cfg_; }
  /// The voxel holding world point p, or null where nothing was allocated.
  const Voxel* voxel_at(const Eigen::Vector3d& p) const;

 private:
  struct Block {
    std::array<Voxel, kBlock * kBlock * kBlock> v;
    std::uint64_t stamp = 0;  // of the last integrate() that changed it
    std::uint64_t generation = 0;  // the owner's generation_ when made: older ones may be shared with a copy
  };
  class Reader;
  TsdfVolume(const TsdfVolume& other, std::uint64_t generation);
  /// The block at `slot`, copied first when a share()d copy may hold it.
  Block& writable(std::shared_ptr<Block>& slot);
  static BlockKey key(int bx, int by, int bz);
  static Eigen::Vector3i unkey(BlockKey k);
  const Voxel* voxel(const Eigen::Vector3i& ijk) const;
  /// The surface point of the voxel cell with first corner o, if the surface passes through it; c: its corners
  /// (x fastest), null where a voxel does not count (min_weight).
  bool cell_surface(const std::array<const Voxel*, 8>& c, const Eigen::Vector3i& o, SurfacePoint& out) const;

  TsdfConfig cfg_;
  std::unordered_map<BlockKey, std::shared_ptr<Block>> blocks_;
  std::uint64_t stamp_ = 0, epoch_ = 0;
  std::uint64_t generation_ = 0;  // advanced by share(): blocks made before it are written only after a copy
};

}  // namespace varslam::dense
