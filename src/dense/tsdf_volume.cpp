#include "dense/tsdf_volume.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace varslam::dense {

namespace {

constexpr int kB = TsdfVolume::kBlock;
constexpr int kBias = 1 << 20;  // block coordinates are stored biased by this in 21 bits each

std::uint64_t pack(int x, int y, int z) {
  return (static_cast<std::uint64_t>(x + kBias) << 42) | (static_cast<std::uint64_t>(y + kBias) << 21) |
         static_cast<std::uint64_t>(z + kBias);
}

int local_index(int x, int y, int z) { return (z * kB + y) * kB + x; }

}  // namespace

TsdfVolume::TsdfVolume(const TsdfConfig& cfg) : cfg_(cfg) {
  if (!(cfg.voxel_size > 0) || !(cfg.truncation_voxels > 0) || !(cfg.max_range > cfg.min_range))
    throw std::invalid_argument("TsdfVolume: voxel size and truncation must be positive, max_range > min_range");
}

TsdfVolume::TsdfVolume(const TsdfVolume& other, std::uint64_t generation)
    : cfg_(other.cfg_), blocks_(other.blocks_), stamp_(other.stamp_), epoch_(other.epoch_), generation_(generation) {}

std::shared_ptr<const TsdfVolume> TsdfVolume::share() {
  std::shared_ptr<const TsdfVolume> copy(new TsdfVolume(*this, generation_));
  ++generation_;
  return copy;
}

TsdfVolume::Block& TsdfVolume::writable(std::shared_ptr<Block>& slot) {
  if (slot->generation != generation_) {
    slot = std::make_shared<Block>(*slot);
    slot->generation = generation_;
  }
  return *slot;
}

TsdfVolume::BlockKey TsdfVolume::key(int bx, int by, int bz) { return pack(bx, by, bz); }

Eigen::Vector3i TsdfVolume::unkey(BlockKey k) {
  const auto mask = (std::uint64_t{1} << 21) - 1;
  return {static_cast<int>((k >> 42) & mask) - kBias, static_cast<int>((k >> 21) & mask) - kBias,
          static_cast<int>(k & mask) - kBias};
}

const Voxel* TsdfVolume::voxel(const Eigen::Vector3i& ijk) const {
  const int bx = floor_div(ijk.x(), kB), by = floor_div(ijk.y(), kB), bz = floor_div(ijk.z(), kB);
  const auto it = blocks_.find(key(bx, by, bz));
  if (it == blocks_.end()) return nullptr;
  return &it->second->v[local_index(ijk.x() - bx * kB, ijk.y() - by * kB, ijk.z() - bz * kB)];
}

const Voxel* TsdfVolume::voxel_at(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d g = p / cfg_.voxel_size;
  return voxel({static_cast<int>(std::floor(g.x())), static_cast<int>(std::floor(g.y())),
                static_cast<int>(std::floor(g.z()))});
}

std::size_t TsdfVolume::observed_voxels() const {
  std::size_t n = 0;
  for (const auto& [k, b] : blocks_)
    for (const Voxel& v : b->v) n += v.weight >= static_cast<float>(cfg_.min_weight) ? 1 : 0;
  return n;
}

IntegrationStats TsdfVolume::integrate(const DepthView& view, int sign, const std::atomic<bool>* cancel) {
  if (view.depth.type() != CV_32FC1 || view.depth.cols != view.camera.width || view.depth.rows != view.camera.height)
    throw std::invalid_argument("TsdfVolume::integrate: depth must be CV_32FC1 of the camera's size");
  const bool have_movers = !view.movers.empty(), have_colour = !view.bgr.empty();
  if (have_movers && (view.movers.type() != CV_8UC1 || view.movers.size() != view.depth.size()))
    throw std::invalid_argument("TsdfVolume::integrate: mover mask must be CV_8UC1 of the depth's size");
  if (have_colour && (view.bgr.type() != CV_8UC3 || view.bgr.size() != view.depth.size()))
    throw std::invalid_argument("TsdfVolume::integrate: colour must be CV_8UC3 of the depth's size");
  IntegrationStats st;
  ++stamp_;
  const double vs = cfg_.voxel_size, trunc = cfg_.truncation(), block_m = vs * kB;
  const PinholeCamera& cam = view.camera;
  const float min_r = static_cast<float>(cfg_.min_range), max_r = static_cast<float>(cfg_.max_range);

  // 1. Blocks around every surface sample (within the truncation band), allocated when fusing.
  if (sign > 0) {
    const Eigen::Matrix3d R = view.T_wc.rotation();
    const Eigen::Vector3d o = view.T_wc.translation();
    const double step = block_m * 0.5;
    for (int v = 0; v < view.depth.rows; ++v) {
      const float* d_row = view.depth.ptr<float>(v);
      const std::uint8_t* m_row = have_movers ? view.movers.ptr<std::uint8_t>(v) : nullptr;
      for (int u = 0; u < view.depth.cols; ++u) {
        const float d = d_row[u];
        if (!(d >= min_r && d <= max_r)) continue;
        if (m_row && m_row[u]) {
          ++st.pixels_moving;
          continue;
        }
        ++st.pixels_used;
        const Eigen::Vector3d ray = R * Eigen::Vector3d((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
        const int n = static_cast<int>(std::ceil(2 * trunc / step));
        for (int s = 0; s <= n; ++s) {
          const double z = d - trunc + 2 * trunc * s / std::max(n, 1);
          if (z <= 0) continue;
          const Eigen::Vector3d p = o + ray * z;
          const auto [it, made] = blocks_.try_emplace(key(static_cast<int>(std::floor(p.x() / block_m)),
                                                          static_cast<int>(std::floor(p.y() / block_m)),
                                                          static_cast<int>(std::floor(p.z() / block_m))));
          if (made) {
            it->second = std::make_shared<Block>();
            it->second->generation = generation_;
          }
        }
      }
    }
  }

  // 2. Every block in the view: its voxels are projected into the image and updated.
  const Eigen::Isometry3d T_cw = view.T_wc.inverse();
  const Eigen::Matrix3f Rcw = T_cw.rotation().cast<float>();
  const Eigen::Vector3f tcw = T_cw.translation().cast<float>();
  const double half_diag = block_m * std::sqrt(3.0) * 0.5;
  const auto fx = static_cast<float>(cam.fx), fy = static_cast<float>(cam.fy), cx = static_cast<float>(cam.cx),
             cy = static_cast<float>(cam.cy);
  const auto trunc_f = static_cast<float>(trunc), sgn = static_cast<float>(sign);
  const auto keep_free = static_cast<float>(cfg_.carve ? cfg_.keep_free_votes : 0);
  for (auto& [k, slot] : blocks_) {
    if (cancel && cancel->load(std::memory_order_relaxed)) {
      st.cancelled = true;
      return st;
    }
    const Eigen::Vector3i b = unkey(k);
    const Eigen::Vector3d centre = (b.cast<double>() + Eigen::Vector3d::Constant(0.5)) * block_m;
    const Eigen::Vector3d c = T_cw * centre;
    if (c.z() + half_diag < cfg_.min_range || c.z() - half_diag > cfg_.max_range + trunc) continue;
    if (c.z() > half_diag) {  // wholly in front of the camera: cull by the image bounds
      const double zn = c.z() - half_diag;
      const double ru = half_diag * cam.fx / zn, rv = half_diag * cam.fy / zn;
      const double u = cam.fx * c.x() / c.z() + cam.cx, v = cam.fy * c.y() / c.z() + cam.cy;
      if (u + ru < -0.5 || v + rv < -0.5 || u - ru > cam.width - 0.5 || v - rv > cam.height - 0.5) continue;
    }
    bool touched = false;
    for (int z = 0; z < kB; ++z)
      for (int y = 0; y < kB; ++y)
        for (int x = 0; x < kB; ++x) {
          const Eigen::Vector3f pw = ((b * kB + Eigen::Vector3i(x, y, z)).cast<float>() + Eigen::Vector3f::Constant(0.5f)) *
                                     static_cast<float>(vs);
          const Eigen::Vector3f pc = Rcw * pw + tcw;
          if (pc.z() < 0.05f) continue;  // at the lens: nothing to fuse (and no overflow in the projection)
          const float uf = fx * pc.x() / pc.z() + cx, vf = fy * pc.y() / pc.z() + cy;
          const int ui = static_cast<int>(std::lround(uf)), vi = static_cast<int>(std::lround(vf));
          if (ui < 0 || vi < 0 || ui >= view.depth.cols || vi >= view.depth.rows) continue;
          const float d = view.depth.at<float>(vi, ui);
          if (!(d >= min_r)) continue;
          // Beyond the range the surface is not fused, but the ray still shows the space before it empty (up to the
          // range): a mover seen against a far wall is cleared by the frames that see the wall again.
          const bool far = d > max_r;
          const float sdf = d - pc.z();
          if (far && (pc.z() > max_r || sdf <= trunc_f)) continue;
          if (sdf < -trunc_f) continue;
          const bool free_space = sdf > trunc_f;
          if (free_space ? !cfg_.carve : have_movers && view.movers.at<std::uint8_t>(vi, ui)) continue;
          Voxel& vox = writable(slot).v[local_index(x, y, z)];
          if (free_space) {
            vox.sdf_sum += sgn;
            vox.weight += sgn;
            ++st.voxels_carved;
          } else {
            // Space seen empty again and again that now shows a surface: something moved into it (a mover no filter
            // knew). It adds one more free observation instead; a static surface is never seen through like that.
            if (keep_free > 0 && sign > 0 && vox.weight >= keep_free && vox.sdf_sum >= vox.weight - 1e-3f) {
              vox.sdf_sum += 1.0f;
              vox.weight += 1.0f;
              ++st.voxels_kept_free;
              touched = true;
              continue;
            }
            vox.sdf_sum += sgn * (sdf / trunc_f);
            vox.weight += sgn;
            if (have_colour) {
              const cv::Vec3b col = view.bgr.at<cv::Vec3b>(vi, ui);
              for (int ch = 0; ch < 3; ++ch) vox.bgr_sum[static_cast<std::size_t>(ch)] += sgn * col[ch];
              vox.colour_weight += sgn;
            }
            ++st.voxels_updated;
          }
          if (vox.weight <= 0.0f) vox = Voxel{};  // taken out again (or more than was put in): unobserved
          touched = true;
        }
    if (touched) {
      ++st.blocks_touched;
      slot->stamp = stamp_;
    }
  }
  return st;
}

// Reads the voxels that count (min_weight) by global coordinate, remembering the last block (meshing walks block by
// block).
class TsdfVolume::Reader {
 public:
  explicit Reader(const TsdfVolume& vol) : vol_(vol), min_w_(static_cast<float>(vol.cfg_.min_weight)) {}
  const Voxel* operator()(const Eigen::Vector3i& ijk) {
    const int bx = floor_div(ijk.x(), kB), by = floor_div(ijk.y(), kB), bz = floor_div(ijk.z(), kB);
    const BlockKey k = key(bx, by, bz);
    if (k != cached_key_) {
      const auto it = vol_.blocks_.find(k);
      cached_key_ = k;
      cached_ = it == vol_.blocks_.end() ? nullptr : it->second.get();
    }
    if (!cached_) return nullptr;
    const Voxel* v = &cached_->v[local_index(ijk.x() - bx * kB, ijk.y() - by * kB, ijk.z() - bz * kB)];
    return v->weight >= min_w_ ? v : nullptr;
  }

 private:
  const TsdfVolume& vol_;
  float min_w_;
  BlockKey cached_key_ = ~BlockKey{0};
  const Block* cached_ = nullptr;
};

bool TsdfVolume::cell_surface(const std::array<const Voxel*, 8>& c, const Eigen::Vector3i& o,
                              SurfacePoint& out) const {
  static const int kEdges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                    {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  const float vs = static_cast<float>(cfg_.voxel_size);
  const auto centre = [vs](const Eigen::Vector3i& ijk) {
    return Eigen::Vector3f((static_cast<float>(ijk.x()) + 0.5f) * vs, (static_cast<float>(ijk.y()) + 0.5f) * vs,
                           (static_cast<float>(ijk.z()) + 0.5f) * vs);
  };
  if (!c[0] || std::abs(c[0]->sdf()) >= 1.0f) return false;
  bool inside = false, outside = false;
  for (const Voxel* v : c) {
    if (!v) return false;
    (v->sdf() < 0 ? inside : outside) = true;
  }
  if (!inside || !outside) return false;
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  int n = 0;
  for (const auto& e : kEdges) {
    const float sa = c[static_cast<std::size_t>(e[0])]->sdf(), sb = c[static_cast<std::size_t>(e[1])]->sdf();
    if ((sa < 0) == (sb < 0)) continue;
    if (std::abs(sa - sb) > 1.0f) return false;  // +free against -surface: not a crossing of one surface
    const float t = sa / (sa - sb);
    const Eigen::Vector3f pa = centre(o + Eigen::Vector3i(e[0] & 1, (e[0] >> 1) & 1, (e[0] >> 2) & 1));
    const Eigen::Vector3f pb = centre(o + Eigen::Vector3i(e[1] & 1, (e[1] >> 1) & 1, (e[1] >> 2) & 1));
    sum += pa + t * (pb - pa);
    ++n;
  }
  if (n == 0) return false;
  // Colour: the corner nearest the surface that has colour.
  const Voxel* best = nullptr;
  for (const Voxel* cv : c)
    if (cv->colour_weight > 0 && (!best || std::abs(cv->sdf()) < std::abs(best->sdf()))) best = cv;
  out.rgb = {200, 200, 200};
  if (best)
    for (int ch = 0; ch < 3; ++ch)
      out.rgb[static_cast<std::size_t>(2 - ch)] = static_cast<std::uint8_t>(
          std::clamp(best->bgr_sum[static_cast<std::size_t>(ch)] / best->colour_weight, 0.0f, 255.0f));
  out.position = sum / static_cast<float>(n);
  return true;
}

std::vector<TsdfVolume::BlockKey> TsdfVolume::changed_since(std::uint64_t since) const {
  std::vector<BlockKey> out;
  for (const auto& [k, b] : blocks_) {
    if (b->stamp <= since) continue;
    const Eigen::Vector3i c = unkey(k);
    for (int i = 0; i < 8; ++i) {
      const BlockKey n = key(c.x() - (i & 1), c.y() - ((i >> 1) & 1), c.z() - ((i >> 2) & 1));
      if (i == 0 || blocks_.count(n)) out.push_back(n);
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void TsdfVolume::block_surface(BlockKey k, std::vector<SurfacePoint>& out) const {
  const auto it = blocks_.find(k);
  if (it == blocks_.end()) return;
  // The block's voxels and the first layer of its +x, +y, +z neighbours (what its cells read), looked up once.
  constexpr int N = kB + 1;
  const Eigen::Vector3i b = unkey(k);
  std::array<const Block*, 8> near{};
  for (int i = 0; i < 8; ++i) {
    const auto n = blocks_.find(key(b.x() + (i & 1), b.y() + ((i >> 1) & 1), b.z() + ((i >> 2) & 1)));
    near[static_cast<std::size_t>(i)] = n == blocks_.end() ? nullptr : n->second.get();
  }
  const auto min_w = static_cast<float>(cfg_.min_weight);
  std::array<const Voxel*, N * N * N> v{};
  for (int z = 0; z < N; ++z)
    for (int y = 0; y < N; ++y)
      for (int x = 0; x < N; ++x) {
        const Block* blk = near[static_cast<std::size_t>((x / kB) | ((y / kB) << 1) | ((z / kB) << 2))];
        if (!blk) continue;
        const Voxel* vox = &blk->v[local_index(x % kB, y % kB, z % kB)];
        if (vox->weight >= min_w) v[static_cast<std::size_t>((z * N + y) * N + x)] = vox;
      }
  SurfacePoint p;
  std::array<const Voxel*, 8> c{};
  for (int z = 0; z < kB; ++z)
    for (int y = 0; y < kB; ++y)
      for (int x = 0; x < kB; ++x) {
        for (int i = 0; i < 8; ++i)
          c[static_cast<std::size_t>(i)] =
              v[static_cast<std::size_t>(((z + ((i >> 2) & 1)) * N + y + ((i >> 1) & 1)) * N + x + (i & 1))];
        if (cell_surface(c, b * kB + Eigen::Vector3i(x, y, z), p)) out.push_back(p);
      }
}

Mesh TsdfVolume::extract_mesh() const {
  Mesh mesh;
  const auto min_w = static_cast<float>(cfg_.min_weight);
  std::vector<BlockKey> keys;
  keys.reserve(blocks_.size());
  for (const auto& [k, b] : blocks_) keys.push_back(k);
  std::sort(keys.begin(), keys.end());
  Reader at(*this);
  auto cell_key = [](const Eigen::Vector3i& c) { return pack(c.x(), c.y(), c.z()); };

  // 1. One vertex per cell (8 voxel centres) the surface passes through.
  std::unordered_map<std::uint64_t, std::int32_t> cell_vertex;
  SurfacePoint p;
  std::array<const Voxel*, 8> c{};
  for (const BlockKey k : keys) {
    const Eigen::Vector3i b = unkey(k) * kB;
    const Block& block = *blocks_.at(k);
    for (int z = 0; z < kB; ++z)
      for (int y = 0; y < kB; ++y)
        for (int x = 0; x < kB; ++x) {
          const Eigen::Vector3i o = b + Eigen::Vector3i(x, y, z);
          const Voxel& v0 = block.v[local_index(x, y, z)];
          if (v0.weight < min_w || std::abs(v0.sdf()) >= 1.0f) continue;  // no surface: skip the corner lookups
          for (int i = 0; i < 8; ++i)
            c[static_cast<std::size_t>(i)] = at(o + Eigen::Vector3i(i & 1, (i >> 1) & 1, (i >> 2) & 1));
          if (!cell_surface(c, o, p)) continue;
          cell_vertex.emplace(cell_key(o), static_cast<std::int32_t>(mesh.vertices.size()));
          mesh.vertices.push_back(p.position);
          mesh.colours.push_back(p.rgb);
        }
  }

  // 2. One quad per voxel edge with a sign change, joining the vertices of the four cells around it.
  for (const BlockKey k : keys) {
    const Eigen::Vector3i b = unkey(k) * kB;
    const Block& block = *blocks_.at(k);
    for (int z = 0; z < kB; ++z)
      for (int y = 0; y < kB; ++y)
        for (int x = 0; x < kB; ++x) {
          const Voxel& va = block.v[local_index(x, y, z)];
          if (va.weight < min_w || std::abs(va.sdf()) >= 1.0f) continue;
          const Eigen::Vector3i a = b + Eigen::Vector3i(x, y, z);
          for (int axis = 0; axis < 3; ++axis) {
            const Eigen::Vector3i e = Eigen::Vector3i::Unit(axis);
            const Voxel* vb = at(a + e);
            if (!vb || (va.sdf() < 0) == (vb->sdf() < 0) || std::abs(va.sdf() - vb->sdf()) > 1.0f) continue;
            const Eigen::Vector3i eu = Eigen::Vector3i::Unit((axis + 1) % 3), ew = Eigen::Vector3i::Unit((axis + 2) % 3);
            const Eigen::Vector3i cells[4] = {a, a - eu, a - eu - ew, a - ew};
            std::array<std::int32_t, 4> q{};
            bool ok = true;
            for (int i = 0; i < 4 && ok; ++i) {
              const auto it = cell_vertex.find(cell_key(cells[i]));
              if (it == cell_vertex.end()) ok = false;
              else q[static_cast<std::size_t>(i)] = it->second;
            }
            if (!ok) continue;
            if (va.sdf() < 0) {  // inside at a: the surface faces +axis
              mesh.triangles.push_back({q[0], q[1], q[2]});
              mesh.triangles.push_back({q[0], q[2], q[3]});
            } else {
              mesh.triangles.push_back({q[0], q[2], q[1]});
              mesh.triangles.push_back({q[0], q[3], q[2]});
            }
          }
        }
  }
  return mesh;
}

std::vector<OccupancyVoxel> TsdfVolume::occupancy() const {
  std::vector<BlockKey> keys;
  keys.reserve(blocks_.size());
  for (const auto& [k, b] : blocks_) keys.push_back(k);
  std::sort(keys.begin(), keys.end());
  const auto min_w = static_cast<float>(cfg_.min_weight);
  const auto shell = static_cast<float>(-2.0 / cfg_.truncation_voxels);  // two voxels behind the zero crossing
  const auto vs = static_cast<float>(cfg_.voxel_size);
  std::vector<OccupancyVoxel> out;
  for (const BlockKey k : keys) {
    const Eigen::Vector3i b = unkey(k) * kB;
    const Block& block = *blocks_.at(k);
    for (int z = 0; z < kB; ++z)
      for (int y = 0; y < kB; ++y)
        for (int x = 0; x < kB; ++x) {
          const Voxel& v = block.v[local_index(x, y, z)];
          if (v.weight < min_w) continue;
          const float s = v.sdf();
          if (s <= 0 && s < shell) continue;  // deep behind a surface: unknown
          const Eigen::Vector3f c =
              ((b + Eigen::Vector3i(x, y, z)).cast<float>() + Eigen::Vector3f::Constant(0.5f)) * vs;
          out.push_back({c, s <= 0});
        }
  }
  return out;
}

}  // namespace varslam::dense
