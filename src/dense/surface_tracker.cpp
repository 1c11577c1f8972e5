#include "dense/surface_tracker.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "dense/dense_mapper.hpp"

namespace varslam::dense {

SurfaceTracker::SurfaceTracker(int cell_voxels, double voxel_size) : cell_(cell_voxels), voxel_size_(voxel_size) {
  if (cell_voxels != 1 && cell_voxels != 2 && cell_voxels != 4 && cell_voxels != 8)
    throw std::invalid_argument("SurfaceTracker: cell_voxels must be 1, 2, 4 or 8, not " + std::to_string(cell_voxels));
  if (!(voxel_size > 0)) throw std::invalid_argument("SurfaceTracker: voxel size must be positive");
}

SurfaceTracker::RegionKey SurfaceTracker::region_of(TsdfVolume::BlockKey block) const {
  const Eigen::Vector3i b = TsdfVolume::block_coords(block);
  return TsdfVolume::block_key({floor_div(b.x(), kRegionBlocks), floor_div(b.y(), kRegionBlocks),
                                floor_div(b.z(), kRegionBlocks)});
}

// One point per cell: the mean position and colour of the block's surface points in it, in cell order.
std::vector<SurfacePoint> SurfaceTracker::thin(TsdfVolume::BlockKey block, const std::vector<SurfacePoint>& points) const {
  if (cell_ == 1 || points.empty()) return points;
  struct Acc {
    std::uint32_t cell;
    Eigen::Vector3f sum;
    std::array<std::uint32_t, 3> rgb;
    std::uint32_t n;
  };
  const int per_block = TsdfVolume::kBlock / cell_;
  const Eigen::Vector3i first = TsdfVolume::block_coords(block) * TsdfVolume::kBlock;
  std::vector<Acc> cells;
  for (const SurfacePoint& p : points) {
    // A point lies between the centres of its voxel cell's first and last corners: the first corner is the voxel
    // at floor(p / voxel - 0.5), in this block (clamped for a point exactly on the far side).
    std::array<std::uint32_t, 3> c{};
    for (int a = 0; a < 3; ++a) {
      const int o = static_cast<int>(std::floor(p.position[a] / voxel_size_ - 0.5)) - first[a];
      c[static_cast<std::size_t>(a)] = static_cast<std::uint32_t>(std::clamp(o, 0, TsdfVolume::kBlock - 1) / cell_);
    }
    const std::uint32_t key = (c[2] * static_cast<std::uint32_t>(per_block) + c[1]) * static_cast<std::uint32_t>(per_block) + c[0];
    auto it = std::find_if(cells.begin(), cells.end(), [&](const Acc& a) { return a.cell == key; });
    if (it == cells.end()) it = cells.insert(cells.end(), Acc{key, Eigen::Vector3f::Zero(), {0, 0, 0}, 0});
    it->sum += p.position;
    for (std::size_t ch = 0; ch < 3; ++ch) it->rgb[ch] += p.rgb[ch];
    ++it->n;
  }
  std::sort(cells.begin(), cells.end(), [](const Acc& a, const Acc& b) { return a.cell < b.cell; });
  std::vector<SurfacePoint> out;
  out.reserve(cells.size());
  for (const Acc& a : cells) {
    SurfacePoint p;
    p.position = a.sum / static_cast<float>(a.n);
    for (std::size_t ch = 0; ch < 3; ++ch) p.rgb[ch] = static_cast<std::uint8_t>(a.rgb[ch] / a.n);
    out.push_back(p);
  }
  return out;
}

std::vector<SurfaceTracker::RegionKey> SurfaceTracker::update(const DenseMapper& map) {
  return update(*map.snapshot());
}

std::vector<SurfaceTracker::RegionKey> SurfaceTracker::update(const TsdfVolume& volume) {
  std::vector<RegionKey> changed;
  if (volume.epoch() != epoch_) {  // fused again from scratch: start over
    for (const auto& [k, pts] : blocks_) changed.push_back(region_of(k));
    blocks_.clear();
    epoch_ = volume.epoch();
    stamp_ = 0;
  }
  std::vector<SurfacePoint> read;
  for (const TsdfVolume::BlockKey k : volume.changed_since(stamp_)) {
    read.clear();
    volume.block_surface(k, read);
    std::vector<SurfacePoint> pts = thin(k, read);
    const auto it = blocks_.find(k);
    if (pts.empty() && it == blocks_.end()) continue;
    changed.push_back(region_of(k));
    if (pts.empty()) blocks_.erase(it);
    else blocks_[k] = std::move(pts);
  }
  stamp_ = volume.stamp();
  std::sort(changed.begin(), changed.end());
  changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
  return changed;
}

std::vector<SurfacePoint> SurfaceTracker::region_points(RegionKey region) const {
  std::vector<SurfacePoint> out;
  const Eigen::Vector3i r = region_index(region) * kRegionBlocks;
  for (int z = 0; z < kRegionBlocks; ++z)
    for (int y = 0; y < kRegionBlocks; ++y)
      for (int x = 0; x < kRegionBlocks; ++x) {
        const auto it = blocks_.find(TsdfVolume::block_key(r + Eigen::Vector3i(x, y, z)));
        if (it != blocks_.end()) out.insert(out.end(), it->second.begin(), it->second.end());
      }
  return out;
}

std::vector<SurfacePoint> SurfaceTracker::all_points() const {
  std::vector<TsdfVolume::BlockKey> keys;
  keys.reserve(blocks_.size());
  for (const auto& [k, pts] : blocks_) keys.push_back(k);
  std::sort(keys.begin(), keys.end());
  std::vector<SurfacePoint> out;
  out.reserve(point_count());
  for (const auto k : keys) {
    const auto& pts = blocks_.at(k);
    out.insert(out.end(), pts.begin(), pts.end());
  }
  return out;
}

std::size_t SurfaceTracker::point_count() const {
  std::size_t n = 0;
  for (const auto& [k, pts] : blocks_) n += pts.size();
  return n;
}

}  // namespace varslam::dense
