#include "dense/dense_mapper.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <optional>
#include <octomap/OcTree.h>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include "core/elapsed.hpp"
#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/settings_registry.hpp"

namespace varslam::dense {

DenseConfig dense_config(const Settings& s) {
  DenseConfig c;
  c.enabled = setting<bool>(s, "dense.enabled");
  c.tsdf.voxel_size = setting<double>(s, "dense.voxel_size");
  c.tsdf.truncation_voxels = setting<double>(s, "dense.truncation_voxels");
  c.tsdf.min_range = setting<double>(s, "dense.min_range");
  c.tsdf.max_range = setting<double>(s, "dense.max_range");
  c.tsdf.min_weight = setting<int>(s, "dense.min_weight");
  c.tsdf.carve = setting<bool>(s, "dense.clear_free_space");
  c.tsdf.keep_free_votes = setting<int>(s, "dense.keep_free_votes");
  c.pixel_step = setting<int>(s, "dense.pixel_step");
  c.exclude_movers = setting<bool>(s, "dense.exclude_movers");
  c.point_radius_px = static_cast<float>(setting<double>(s, "dense.moving_point_radius_px"));
  c.margin_px = setting<int>(s, "dense.mover_margin_px");
  c.reintegrate_m = setting<double>(s, "dense.reintegrate_m");
  c.reintegrate_deg = setting<double>(s, "dense.reintegrate_deg");
  if (c.tsdf.max_range <= c.tsdf.min_range)
    throw ConfigError(fmt::format("dense.max_range ({}) must be above dense.min_range ({})", c.tsdf.max_range,
                                  c.tsdf.min_range));
  return c;
}

namespace {

PinholeCamera scaled(const PinholeCamera& c, int step) {
  PinholeCamera s = c;
  const double k = 1.0 / step;
  s.fx = c.fx * k;
  s.fy = c.fy * k;
  s.cx = (c.cx + 0.5) * k - 0.5;
  s.cy = (c.cy + 0.5) * k - 0.5;
  s.width = c.width / step;
  s.height = c.height / step;
  return s;
}

// Every step-th pixel (no averaging across depth edges): the pixel nearest each sample's centre.
cv::Mat subsample(const cv::Mat& m, int step, int w, int h) {
  if (step == 1) return m.clone();
  cv::Mat out(h, w, m.type());
  const int off = step / 2;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u)
      std::memcpy(out.ptr(v, u), m.ptr(v * step + off, u * step + off), m.elemSize());
  return out;
}

// A mover pixel anywhere in the step x step cell marks the cell.
cv::Mat max_pool(const cv::Mat& m, int step, int w, int h) {
  if (step == 1) return m.clone();
  cv::Mat out(h, w, CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < h * step; ++v) {
    const std::uint8_t* row = m.ptr<std::uint8_t>(v);
    std::uint8_t* o = out.ptr<std::uint8_t>(v / step);
    for (int u = 0; u < w * step; ++u)
      if (row[u]) o[u / step] = 255;
  }
  return out;
}

}  // namespace

DenseMapper::DenseMapper(const DenseConfig& cfg, const PinholeCamera& camera, bool threaded)
    : cfg_(cfg), camera_(scaled(camera, std::max(1, cfg.pixel_step))), threaded_(threaded), volume_(cfg.tsdf) {
  std::lock_guard lock(fusion_mutex_);
  publish_locked();
  if (threaded_) thread_ = std::thread([this] { worker(); });
}

DenseMapper::~DenseMapper() {
  {
    std::lock_guard lock(queue_mutex_);
    stop_ = true;
  }
  stop_worker();
}

void DenseMapper::stop_worker() {
  cancel_ = true;
  wake_.notify_all();
  if (!thread_.joinable()) return;
  // The worker runs at idle priority and may be kept off a busy CPU for long: back to normal priority so it sees
  // the cancel at once (allowed where the limits let it; else it sees it when next scheduled).
  sched_param normal{};
  (void)pthread_setschedparam(thread_.native_handle(), SCHED_OTHER, &normal);
  thread_.join();
}

DenseMapper::Stored DenseMapper::prepare(DenseKeyframe kf) const {
  const int step = std::max(1, cfg_.pixel_step);
  Stored s;
  s.id = kf.id;
  s.timestamp = kf.timestamp;
  s.depth = subsample(kf.depth, step, camera_.width, camera_.height);
  if (!kf.bgr.empty() && kf.bgr.type() == CV_8UC3) {
    if (step == 1) s.bgr = kf.bgr.clone();
    else cv::resize(kf.bgr, s.bgr, cv::Size(camera_.width, camera_.height), 0, 0, cv::INTER_AREA);
  }
  if (cfg_.exclude_movers) {
    const cv::Mat m = mover_mask(kf.depth, kf.movers);
    if (cv::countNonZero(m) > 0) s.movers = max_pool(m, step, camera_.width, camera_.height);
  }
  s.pose = std::move(kf.pose);
  return s;
}

void DenseMapper::add(DenseKeyframe kf) {
  if (kf.depth.type() != CV_32FC1) throw std::invalid_argument("DenseMapper::add: depth must be CV_32FC1");
  if (threaded_) {
    {
      std::lock_guard lock(queue_mutex_);
      if (finished_) throw std::logic_error("DenseMapper::add after finish()");
      pending_.push_back(std::move(kf));
      ++keyframes_;
    }
    wake_.notify_one();
    return;
  }
  Stored s = prepare(std::move(kf));
  std::lock_guard lock(queue_mutex_);
  if (finished_) throw std::logic_error("DenseMapper::add after finish()");
  arrived_.push_back(std::move(s));
  ++keyframes_;
}

void DenseMapper::take_arrived_locked() {
  std::lock_guard lock(queue_mutex_);
  if (arrived_.empty()) return;
  for (Stored& s : arrived_) store_.push_back(std::move(s));
  arrived_.clear();
  dirty_ = true;
}

DepthView DenseMapper::view_of(const Stored& s, const Eigen::Isometry3d& T_wc) const {
  DepthView v;
  v.depth = s.depth;
  v.bgr = s.bgr;
  v.movers = s.movers;
  v.camera = camera_;
  v.T_wc = T_wc;
  return v;
}

bool DenseMapper::moved(const Stored& s, const Eigen::Isometry3d& now) const {
  const double dt = (now.translation() - s.fused_pose.translation()).norm();
  const double da = Eigen::AngleAxisd(now.rotation().transpose() * s.fused_pose.rotation()).angle() * 180.0 / M_PI;
  return dt > cfg_.reintegrate_m || da > cfg_.reintegrate_deg;
}

bool DenseMapper::fuse_locked(Stored& s, bool preview, const std::atomic<bool>* cancel) {
  const auto t0 = std::chrono::steady_clock::now();
  const Eigen::Isometry3d now = s.pose();
  if (s.fused) {
    if (volume_.integrate(view_of(s, s.fused_pose), -1, cancel).cancelled) return false;
    if (!preview) ++stats_.reintegrations;
  }
  const IntegrationStats st = volume_.integrate(view_of(s, now), +1, cancel);
  if (st.cancelled) return false;
  used_pixels_ += st.pixels_used;
  moving_pixels_ += st.pixels_moving;
  s.fused = true;
  s.fused_pose = now;
  if (preview) {
    ++stats_.preview_fusions;
  } else {
    ++stats_.integrations;
    stats_.integrate_ms.push_back(ms_since(t0));
  }
  return true;
}

bool DenseMapper::fuse_one_locked(bool preview, const std::atomic<bool>* cancel) {
  if (next_to_fuse_ < store_.size()) return fuse_locked(store_[next_to_fuse_++], preview, cancel);
  // Then the keyframes whose pose moved since they were fused (one at a time: new keyframes come first).
  for (Stored& s : store_)
    if (s.fused && moved(s, s.pose())) return fuse_locked(s, preview, cancel);
  return false;
}

void DenseMapper::rebuild_locked() {
  volume_.clear();
  used_pixels_ = moving_pixels_ = 0;
  for (Stored& s : store_) {
    s.fused = false;
    fuse_locked(s, false);
  }
  next_to_fuse_ = store_.size();
  ++stats_.rebuilds;
  dirty_ = false;
}

void DenseMapper::publish_locked() {
  auto p = std::make_shared<Published>();
  p->volume = volume_.share();
  p->stats = stats_;
  p->stats.blocks = volume_.block_count();
  const std::size_t all = used_pixels_ + moving_pixels_;
  p->stats.moving_pixel_share = all ? static_cast<double>(moving_pixels_) / static_cast<double>(all) : 0.0;
  std::lock_guard lock(published_mutex_);
  published_ = std::move(p);
}

void DenseMapper::worker() {
  // Below tracking and local mapping: the dense map runs only on a core nothing else wants (SCHED_IDLE; else at nice
  // +10). On a busy machine it waits, not the pose, and no reader waits for it; finish() fuses what is left.
  sched_param idle{};
  if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &idle) != 0)
    setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 10);
  for (;;) {
    std::optional<DenseKeyframe> kf;
    {
      std::lock_guard lock(queue_mutex_);
      if (stop_) return;
      if (!pending_.empty()) {
        kf = std::move(pending_.front());
        pending_.pop_front();
      }
    }
    bool worked = false;
    {
      std::optional<Stored> s;
      if (kf) s = prepare(std::move(*kf));  // no lock: the mover mask and the downsampling take a while
      std::lock_guard lock(fusion_mutex_);
      if (s) store_.push_back(std::move(*s));
      worked = fuse_one_locked(false, &cancel_);
      if (cancel_) return;  // finish() fuses everything again; the destructor wants nothing more
      if (worked) publish_locked();
    }
    if (worked) continue;
    std::unique_lock lock(queue_mutex_);
    wake_.wait_for(lock, std::chrono::milliseconds(200), [&] { return stop_ || !pending_.empty(); });
  }
}

void DenseMapper::finish() {
  {
    std::lock_guard lock(queue_mutex_);
    if (finished_) return;
    stop_ = true;
  }
  stop_worker();
  std::lock_guard lock(fusion_mutex_);
  std::deque<DenseKeyframe> left;
  {
    std::lock_guard queue(queue_mutex_);
    finished_ = true;
    left.swap(pending_);
  }
  take_arrived_locked();
  for (DenseKeyframe& kf : left) store_.push_back(prepare(std::move(kf)));
  const auto t0 = std::chrono::steady_clock::now();
  rebuild_locked();
  stats_.final_rebuild_ms = ms_since(t0);
  publish_locked();
}

std::shared_ptr<const TsdfVolume> DenseMapper::snapshot() const {
  std::lock_guard lock(published_mutex_);
  return published_->volume;
}

void DenseMapper::bring_up_to_date() {
  if (threaded_) return;  // the worker keeps the snapshot current
  std::lock_guard lock(fusion_mutex_);
  take_arrived_locked();
  if (dirty_) {
    rebuild_locked();
    publish_locked();
  }
}

Mesh DenseMapper::mesh() {
  bring_up_to_date();
  return snapshot()->extract_mesh();
}

std::vector<OccupancyVoxel> DenseMapper::occupancy() {
  bring_up_to_date();
  return snapshot()->occupancy();
}

bool DenseMapper::preview_step() {
  if (threaded_) return false;
  std::lock_guard lock(fusion_mutex_);
  {
    std::lock_guard queue(queue_mutex_);
    if (finished_) return false;
  }
  take_arrived_locked();
  if (!fuse_one_locked(true)) return false;
  dirty_ = true;  // mesh() and occupancy() still fuse everything afresh: the same input gives the same map
  publish_locked();
  return true;
}

DenseStats DenseMapper::stats() const {
  DenseStats s;
  {
    std::lock_guard lock(published_mutex_);
    s = published_->stats;
  }
  std::lock_guard queue(queue_mutex_);
  s.keyframes = keyframes_;
  return s;
}

void write_mesh_ply(const Mesh& mesh, const std::filesystem::path& file) {
  std::string out = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment varslam dense map of the static scene\nelement vertex {}\n"
      "property float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
      mesh.vertices.size(), mesh.triangles.size());
  out.reserve(out.size() + mesh.vertices.size() * 15 + mesh.triangles.size() * 13);
  auto put = [&out](const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); };
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    put(mesh.vertices[i].data(), 12);
    put(mesh.colours[i].data(), 3);
  }
  for (const auto& t : mesh.triangles) {
    const std::uint8_t n = 3;
    put(&n, 1);
    put(t.data(), 12);
  }
  write_file_atomically(file, out, "dense mesh");
}

void write_octomap_bt(const std::vector<OccupancyVoxel>& voxels, double resolution, const std::filesystem::path& file) {
  octomap::OcTree tree(resolution);
  const float occ = tree.getClampingThresMaxLog(), fre = tree.getClampingThresMinLog();
  for (const OccupancyVoxel& v : voxels) {
    octomap::OcTreeKey key;
    if (!tree.coordToKeyChecked(octomap::point3d(v.centre.x(), v.centre.y(), v.centre.z()), key)) continue;
    tree.setNodeValue(key, v.occupied ? occ : fre, false);
  }
  tree.updateInnerOccupancy();
  std::ostringstream s;
  if (!tree.writeBinaryConst(s)) throw InputError(fmt::format("{}: could not encode the occupancy map", file.string()));
  write_file_atomically(file, s.str(), "occupancy map");
}

}  // namespace varslam::dense
