// varslam::Slam: the public session over the internal pipeline (pipeline/slam.hpp), with plain value types, input
// checks and the thread-safe views a consumer thread reads.
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <thread>
#include <varslam/slam.hpp>

#include "api/config_access.hpp"
#include "dense/dense_mapper.hpp"
#include "dense/surface_tracker.hpp"
#include "mapfile/map_file.hpp"
#include "pipeline/slam.hpp"
#include "slam/keyframe.hpp"
#include "slam/map.hpp"
#include "slam/map_point.hpp"
#ifdef VARSLAM_HAVE_VIEWER
#include "viewer/live_viewer.hpp"
#endif

namespace varslam {
namespace detail {
void default_library_log();
}

namespace {

Pose to_pose(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.rotation());
  const Eigen::Vector3d t = T.translation();
  Pose p;
  p.translation = {t.x(), t.y(), t.z()};
  p.rotation = {q.x(), q.y(), q.z(), q.w()};
  return p;
}

std::vector<TimedPose> to_timed(const Trajectory& t) {
  std::vector<TimedPose> out;
  out.reserve(t.size());
  for (const auto& p : t) out.push_back({p.timestamp, to_pose(p.T_wc)});
  return out;
}

TrackingState to_state(slam::TrackState s) {
  switch (s) {
    case slam::TrackState::Ok:
      return TrackingState::Tracking;
    case slam::TrackState::Lost:
      return TrackingState::Lost;
    case slam::TrackState::NotInitialized:
      return TrackingState::NotInitialized;
  }
  return TrackingState::Lost;
}

SessionSummary to_summary(const PipelineSummary& p) {
  return {p.frames, p.tracked, p.keyframes, p.map_points, p.segments, p.relocalizations, p.detector};
}

}  // namespace

struct Slam::Impl final : Observer {
  Settings settings;
  Mode mode;
  std::optional<std::string> map_file;  // loaded again by reset()
  bool localization_only = false;
#ifdef VARSLAM_HAVE_VIEWER
  std::unique_ptr<viewer::LiveViewer> viewer;  // before the pipeline: it observes it, so it must outlive it
#endif
  std::unique_ptr<Pipeline> pipeline;
  std::vector<Listener*> listeners;

  // Held by the tracking thread for a whole frame, and by the calls other threads may make that touch the pipeline.
  // Those announce themselves in `waiting` first and track() lets them in before its next frame, so a caller on
  // another thread is never starved by a tracking loop that takes the lock again at once.
  mutable std::mutex pipeline_mutex;
  mutable std::atomic<int> waiting{0};
  mutable std::mutex views_mutex;  // the three views below
  std::shared_ptr<const MapSnapshot> snapshot = std::make_shared<MapSnapshot>();
  std::vector<TimedPose> live;
  SessionSummary summary;
  mutable std::atomic<bool> snapshot_wanted{false};
  // Follows the dense map's surface between dense_map_snapshot() calls (remade for a new map or cell size).
  mutable std::mutex dense_surface_mutex;
  mutable std::unique_ptr<dense::SurfaceTracker> dense_surface;
  mutable const dense::DenseMapper* dense_surface_of = nullptr;
  mutable int dense_surface_cell = 0;

  std::optional<double> last_timestamp;
  bool relocalized_now = false;

  Impl(const Config& config, Mode m) : settings(detail::ConfigAccess::settings(config)), mode(m) { rebuild(); }

  void rebuild() {
    PipelineOptions o;
    o.mode = mode == Mode::RealTime ? RunMode::RealTime : RunMode::Deterministic;
    auto p = std::make_unique<Pipeline>(settings, std::move(o));
    if (map_file) p->load_map(*map_file);
    if (!map_file) localization_only = false;  // a new session without a map has nothing to localize in
    if (localization_only) p->set_localization_only(true);
    p->add_observer(*this);
#ifdef VARSLAM_HAVE_VIEWER
    if (viewer) p->add_observer(*viewer);
#endif
    pipeline = std::move(p);
    last_timestamp.reset();
    std::lock_guard lock(views_mutex);
    snapshot = std::make_shared<MapSnapshot>();
    live.clear();
    summary = {};
    summary.person_detector = pipeline->summary().detector;
  }

  void check_timestamp(double t) const {
    if (!std::isfinite(t)) throw InputError(fmt::format("frame timestamp {} is not a finite number", t));
    if (last_timestamp && t <= *last_timestamp)
      throw InputError(
          fmt::format("frame timestamp {:.6f} is not after the previous frame's ({:.6f}): timestamps "
                      "must increase",
                      t, *last_timestamp));
  }

  // The pipeline lock for a call from another thread (see `waiting`).
  std::unique_lock<std::mutex> lock_from_other_thread() const {
    ++waiting;
    std::unique_lock lock(pipeline_mutex);
    --waiting;
    return lock;
  }

  TrackedFrame track(const cv::Mat& bgr, const cv::Mat& depth, double t, const std::optional<Detections>& boxes,
                     const cv::Mat& mover_mask = cv::Mat()) {
    while (waiting.load() > 0) std::this_thread::yield();
    std::lock_guard lock(pipeline_mutex);
    check_timestamp(t);
    relocalized_now = false;
    // The detector and the viewer may hold the images after this call: a matrix that wraps the caller's buffer
    // (no reference count: cv_bridge's toCvShare, a Mat over a camera driver's memory) is copied first.
    const cv::Mat own_bgr = bgr.u ? bgr : bgr.clone();
    const cv::Mat own_depth = depth.u ? depth : depth.clone();
    const cv::Mat own_mask = mover_mask.u || mover_mask.empty() ? mover_mask : mover_mask.clone();
    const FrameResult r = pipeline->track(own_bgr, own_depth, t, boxes, own_mask);
    last_timestamp = t;
    TrackedFrame f;
    f.index = r.index;
    f.timestamp = r.timestamp;
    f.state = to_state(r.state);
    if (r.T_wc) f.pose = to_pose(*r.T_wc);
    f.keyframe = r.keyframe;
    f.keyframe_id = r.keyframe_id;
    f.new_segment = r.new_segment;
    f.relocalized = relocalized_now;
    f.keypoints = r.keypoints;
    f.inliers = r.inliers;
    f.map_keyframes = r.map_keyframes;
    f.map_points = r.map_points;
    f.tracking_ms = r.timings.track_ms;
    const PipelineSummary p = pipeline->summary();
    std::size_t snapshot_keyframes = 0;
    {
      std::lock_guard views(views_mutex);
      if (f.pose) live.push_back({t, *f.pose});
      summary = to_summary(p);
      snapshot_keyframes = snapshot->keyframes.size();
    }
    // Also when the map changed without a keyframe of this session (a loaded map adopted, keyframes culled).
    if (r.keyframe || snapshot_wanted.exchange(false) || snapshot_keyframes != r.map_keyframes)
      refresh_snapshot(r.index + 1);
    return f;
  }

  // On the tracking thread: the map's lists are copied under its lock, each point's position under its own.
  void refresh_snapshot(std::size_t frames) {
    auto s = std::make_shared<MapSnapshot>();
    s->frame_index = frames;
    const slam::Map& map = pipeline->map();
    for (const auto& kf : map.keyframes())
      if (!kf->is_bad()) s->keyframes.push_back({kf->id(), kf->timestamp(), to_pose(kf->pose_inverse())});
    for (const auto& mp : map.map_points()) {
      if (mp->is_bad()) continue;
      const Eigen::Vector3d x = mp->position();
      s->points.push_back({mp->id(), {x.x(), x.y(), x.z()}, mp->num_observations()});
    }
    std::lock_guard lock(views_mutex);
    snapshot = std::move(s);
  }

  void on_keyframe_mapped(const slam::KeyframeMapped& m) override {
    if (!m.ba) return;
    const LocalBaInfo info{m.keyframe_id,      m.timestamp,     m.ba->final_alpha,
                           m.ba->fitted_alpha, m.ba->keyframes, m.ba->points,
                           m.ba->observations, m.ba->outliers,  m.ba->ms};
    for (Listener* l : listeners) l->on_local_ba(info);
  }
  void on_loop(const slam::LoopRecord& l) override {
    const LoopInfo info{l.query_keyframe, l.loop_keyframe, l.timestamp, l.correction_m, l.correction_deg};
    for (Listener* x : listeners) x->on_loop(info);
  }
  void on_relocalization(const RelocalizationEvent&) override { relocalized_now = true; }
  void on_detection(const DetectionEvent& e) override {
    PersonBoxesInfo info;
    info.index = e.index;
    info.timestamp = e.timestamp;
    info.box_age_s = e.box_age_s;
    for (const auto& d : e.boxes) info.boxes.push_back({d.box.x, d.box.y, d.box.width, d.box.height, d.score});
    for (Listener* l : listeners) l->on_person_boxes(info);
  }
};

Slam::Slam(const Config& config, Mode mode) {
  detail::default_library_log();
  impl_ = std::make_unique<Impl>(config, mode);
}

Slam::~Slam() = default;

TrackedFrame Slam::track(const cv::Mat& bgr, const cv::Mat& depth, double timestamp) {
  return impl_->track(bgr, depth, timestamp, std::nullopt);
}

namespace {

Detections to_detections(const std::vector<PersonBox>& people, double timestamp) {
  Detections d;
  for (const PersonBox& b : people) {
    if (!std::isfinite(b.x) || !std::isfinite(b.y) || !std::isfinite(b.width) || !std::isfinite(b.height) ||
        b.width <= 0 || b.height <= 0)
      throw InputError(fmt::format("person box ({}, {}, {} x {}) is not a box with finite, positive size", b.x, b.y,
                                   b.width, b.height));
    d.push_back({timestamp, "person", b.score, cv::Rect2f(b.x, b.y, b.width, b.height)});
  }
  return d;
}

}  // namespace

TrackedFrame Slam::track(const cv::Mat& bgr, const cv::Mat& depth, double timestamp,
                         const std::vector<PersonBox>& people) {
  return impl_->track(bgr, depth, timestamp, to_detections(people, timestamp));
}

TrackedFrame Slam::track(const cv::Mat& bgr, const cv::Mat& depth, double timestamp, const FrameExtras& extras) {
  std::optional<Detections> boxes;
  if (extras.people) boxes = to_detections(*extras.people, timestamp);
  return impl_->track(bgr, depth, timestamp, boxes, extras.mover_mask);
}

void Slam::finish() {
  std::lock_guard lock(impl_->pipeline_mutex);
  impl_->pipeline->finish();
  const PipelineSummary p = impl_->pipeline->summary();
  impl_->refresh_snapshot(p.frames);
  std::lock_guard views(impl_->views_mutex);
  impl_->summary = to_summary(p);
}

void Slam::reset() {
  std::lock_guard lock(impl_->pipeline_mutex);
  impl_->rebuild();
}

void Slam::load_map(const std::string& file) {
  std::lock_guard lock(impl_->pipeline_mutex);
  const std::optional<std::string> before = impl_->map_file;
  impl_->map_file = file;
  try {
    impl_->rebuild();
  } catch (...) {
    impl_->map_file = before;
    impl_->rebuild();
    throw;
  }
}

void Slam::set_localization_only(bool on) {
  std::lock_guard lock(impl_->pipeline_mutex);
  if (on && !impl_->map_file && impl_->pipeline->summary().keyframes == 0)
    throw InputError("localization only needs a map to localize in: load_map() first, or track until there is one");
  impl_->pipeline->set_localization_only(on);
  impl_->localization_only = on;
}

void Slam::relocalize_near(const Pose& camera_to_world, double radius_m) {
  const auto& t = camera_to_world.translation;
  const auto& q = camera_to_world.rotation;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const bool finite = std::isfinite(t[0]) && std::isfinite(t[1]) && std::isfinite(t[2]) && std::isfinite(norm);
  if (!finite || std::abs(norm - 1) > 1e-3)
    throw InputError(fmt::format("relocalize_near: the pose ({}, {}, {}; quaternion {}, {}, {}, {}) is not finite "
                                 "with a unit quaternion",
                                 t[0], t[1], t[2], q[0], q[1], q[2], q[3]));
  if (!std::isfinite(radius_m) || radius_m <= 0)
    throw InputError(fmt::format("relocalize_near: radius {} m is not a positive distance", radius_m));
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
  T_wc.linear() = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
  T_wc.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  std::lock_guard lock(impl_->pipeline_mutex);
  impl_->pipeline->relocalize_near(T_wc, radius_m);
}

void Slam::save_map(const std::string& file) {
  // Wait for local mapping to be idle without holding the session, so that tracking goes on meanwhile and the copy
  // below (which pauses mapping between two keyframes) does not wait for a Local BA. Bounded: a map that keeps
  // mapping gets its copy after the keyframe in progress.
  for (int tries = 0; tries < 500; ++tries) {
    {
      const auto lock = impl_->lock_from_other_thread();
      if (impl_->pipeline->mapping_idle()) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  slam::SavedMap map;
  {
    const auto lock = impl_->lock_from_other_thread();
    map = impl_->pipeline->map_to_save(file);
  }
  mapfile::save_map_file(map, file);  // encoding and writing: tracking goes on meanwhile
}

std::shared_ptr<const MapSnapshot> Slam::map_snapshot() const {
  impl_->snapshot_wanted = true;
  std::lock_guard lock(impl_->views_mutex);
  return impl_->snapshot;
}

std::shared_ptr<const DenseMapSnapshot> Slam::dense_map_snapshot() const { return dense_map_snapshot({}); }

std::shared_ptr<const DenseMapSnapshot> Slam::dense_map_snapshot(const DenseMapRequest& request) const {
  const int cell = request.surface_cell_voxels;
  if (request.surface && cell != 1 && cell != 2 && cell != 4 && cell != 8)
    throw ConfigError(fmt::format("DenseMapRequest::surface_cell_voxels: {} is not 1, 2, 4 or 8", cell));
  std::shared_ptr<dense::DenseMapper> d;
  {
    const auto lock = impl_->lock_from_other_thread();
    d = impl_->pipeline->shared_dense_map();
  }
  auto out = std::make_shared<DenseMapSnapshot>();
  if (!d) return out;
  // From the dense map's shared copy from here: neither tracking nor its fusion waits for this reader.
  out->voxel_size = d->config().tsdf.voxel_size;
  out->keyframes = d->stats().keyframes;
  if (request.mesh) {
    const dense::Mesh mesh = d->mesh();
    out->vertices.reserve(mesh.vertices.size());
    for (const auto& v : mesh.vertices) out->vertices.push_back({v.x(), v.y(), v.z()});
    out->colours = mesh.colours;
    out->triangles = mesh.triangles;
  }
  if (request.occupancy)
    for (const auto& v : d->occupancy())
      (v.occupied ? out->occupied : out->free).push_back({v.centre.x(), v.centre.y(), v.centre.z()});
  if (request.surface) {
    std::lock_guard lock(impl_->dense_surface_mutex);
    if (!impl_->dense_surface || impl_->dense_surface_of != d.get() || impl_->dense_surface_cell != cell) {
      impl_->dense_surface = std::make_unique<dense::SurfaceTracker>(cell, out->voxel_size);
      impl_->dense_surface_of = d.get();
      impl_->dense_surface_cell = cell;
    }
    while (d->preview_step()) {  // deterministic mode: the keyframes not fused yet (one per hold of the lock)
    }
    impl_->dense_surface->update(*d);
    for (const dense::SurfacePoint& p : impl_->dense_surface->all_points()) {
      out->surface.push_back({p.position.x(), p.position.y(), p.position.z()});
      out->surface_colours.push_back(p.rgb);
    }
  }
  return out;
}

std::vector<TimedPose> Slam::live_trajectory() const {
  std::lock_guard lock(impl_->views_mutex);
  return impl_->live;
}

std::vector<TimedPose> Slam::camera_trajectory() const {
  const auto lock = impl_->lock_from_other_thread();
  return to_timed(impl_->pipeline->camera_trajectory());
}

SessionSummary Slam::summary() const {
  std::lock_guard lock(impl_->views_mutex);
  return impl_->summary;
}

std::string Slam::start_viewer(const ViewerOptions& options) {
#ifdef VARSLAM_HAVE_VIEWER
  std::lock_guard lock(impl_->pipeline_mutex);
  if (impl_->viewer) return impl_->viewer->url();
  if (!std::isfinite(options.max_frame_rate) || options.max_frame_rate <= 0 || options.port < 0 || options.port > 65535)
    throw InputError(fmt::format("viewer: port {} or frame rate {} out of range (0-65535, > 0)", options.port,
                                 options.max_frame_rate));
  viewer::LiveViewerOptions vo;
  vo.server.address = options.address;
  vo.server.port = options.port;
  vo.max_frame_rate = options.max_frame_rate;
  vo.title = options.title;
  impl_->viewer = std::make_unique<viewer::LiveViewer>(vo);
  impl_->pipeline->add_observer(*impl_->viewer);
  return impl_->viewer->url();
#else
  (void)options;
  throw InputError("viewer: this varslam was built without the viewer (-DVARSLAM_BUILD_VIEWER=OFF)");
#endif
}

void Slam::add_listener(Listener& l) { impl_->listeners.push_back(&l); }

void Slam::remove_listener(Listener& l) {
  auto& v = impl_->listeners;
  v.erase(std::remove(v.begin(), v.end(), &l), v.end());
}

Mode Slam::mode() const { return impl_->mode; }

std::string Slam::version() { return std::string(kVersion); }

}  // namespace varslam
