#include "viewer/dense_layer.hpp"

#include <fmt/format.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "core/elapsed.hpp"
#include "dense/dense_mapper.hpp"
#include "viewer/viewer_messages.hpp"

namespace varslam::viewer {
namespace {

using Clock = std::chrono::steady_clock;

// CPU time of the calling thread (ms): what an update costs, apart from the time an idle-priority thread waits.
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

}  // namespace

DenseLayer::DenseLayer(std::shared_ptr<dense::DenseMapper> map, ViewerBoard& board, const DenseLayerOptions& options)
    : map_(std::move(map)),
      board_(board),
      options_(options),
      tracker_(options.cell_voxels, map_->config().tsdf.voxel_size) {
  if (!(options_.rate > 0)) throw std::invalid_argument("DenseLayer: rate must be positive");
  thread_ = std::thread([this] { loop(); });
}

DenseLayer::~DenseLayer() { stop(); }

void DenseLayer::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

DenseLayerStats DenseLayer::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

void DenseLayer::loop() {
  // Like the dense map's worker: only on a core tracking and local mapping leave free.
  sched_param idle{};
  if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &idle) != 0)
    setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 10);
  const auto period = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::duration<double>(1.0 / options_.rate));
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      if (wake_.wait_for(lock, period, [&] { return stopping_; })) return;
    }
    if (board_.clients() == 0) continue;  // nobody looks: no work
    std::lock_guard update(update_mutex_);
    update_locked(period * 3 / 4);
  }
}

DenseRegionView DenseLayer::region_view(dense::SurfaceTracker::RegionKey region) const {
  DenseRegionView v;
  const Eigen::Vector3i i = dense::SurfaceTracker::region_index(region);
  v.key = fmt::format("{},{},{}", i.x(), i.y(), i.z());
  v.size = tracker_.region_size();
  v.origin = i.cast<double>() * v.size;
  v.cell = tracker_.cell_size();
  return v;
}

bool DenseLayer::stopping() const {
  std::lock_guard lock(mutex_);
  return stopping_;
}

void DenseLayer::clear() {
  stop();
  std::lock_guard update(update_mutex_);
  for (const auto region : posted_) {
    const DenseRegionView v = region_view(region);
    board_.set_dense_region(v.key, sse_event("dense", dense_region_message(v).dump()));
  }
  posted_.clear();
}

void DenseLayer::update() {
  std::lock_guard update(update_mutex_);
  update_locked(std::chrono::milliseconds(0));
}

void DenseLayer::update_locked(std::chrono::milliseconds preview_budget) {
  const auto t0 = Clock::now();
  // Deterministic mode: fuse what came since, one keyframe per hold of the map's lock, within the budget.
  while (Clock::now() - t0 < preview_budget && !stopping() && map_->preview_step()) {
  }
  const double preview_ms = ms_since(t0);
  const auto t1 = Clock::now();
  const double cpu0 = thread_cpu_ms();
  const std::vector<dense::SurfaceTracker::RegionKey> changed = tracker_.update(*map_);
  std::size_t bytes = 0, sent = 0;
  for (const auto region : changed) {
    DenseRegionView v = region_view(region);
    v.points = tracker_.region_points(region);
    if (v.points.empty() && !posted_.count(region)) continue;  // never shown: nothing to take away
    if (v.points.empty()) posted_.erase(region);
    else posted_.insert(region);
    std::string message = sse_event("dense", dense_region_message(v).dump());
    bytes += message.size();
    ++sent;
    board_.set_dense_region(v.key, std::move(message));
  }
  const double ms = ms_since(t1), cpu_ms = thread_cpu_ms() - cpu0;
  std::lock_guard lock(mutex_);
  stats_.max_update_cpu_ms = std::max(stats_.max_update_cpu_ms, cpu_ms);
  stats_.update_cpu_ms += cpu_ms;
  stats_.preview_ms += preview_ms;
  ++stats_.updates;
  stats_.regions_sent += sent;
  stats_.bytes_sent += bytes;
  stats_.points = tracker_.point_count();
  stats_.regions = posted_.size();
  stats_.last_update_ms = ms;
  stats_.max_update_ms = std::max(stats_.max_update_ms, ms);
  stats_.last_update_bytes = bytes;
  stats_.max_update_bytes = std::max(stats_.max_update_bytes, bytes);
}

}  // namespace varslam::viewer
