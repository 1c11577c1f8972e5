#include "viewer/live_viewer.hpp"

#include <opencv2/calib3d.hpp>

#include "pipeline/slam.hpp"

namespace varslam::viewer {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Undistorted keypoint positions back to the pixels of the image shown.
std::vector<cv::Point2f> image_pixels(const slam::FrameFeatures& f) {
  std::vector<cv::Point2f> px(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) px[i] = f.keypoints[i].pt;
  const PinholeCamera& c = f.camera;
  if (!c.has_distortion() || px.empty()) return px;
  std::vector<cv::Point3f> rays(px.size());
  for (std::size_t i = 0; i < px.size(); ++i)
    rays[i] = {static_cast<float>((px[i].x - c.cx) / c.fx), static_cast<float>((px[i].y - c.cy) / c.fy), 1.0f};
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), c.K(), c.dist_coeffs(), px);
  return px;
}

}  // namespace

/// Adds the time a callback took on the tracking thread to the stats.
class LiveViewer::CallbackTimer {
 public:
  explicit CallbackTimer(LiveViewer& v) : v_(v), start_(Clock::now()) {}
  ~CallbackTimer() {
    const double ms = seconds_since(start_) * 1e3;
    std::lock_guard lock(v_.mutex_);
    v_.stats_.observer_ms_total += ms;
    v_.stats_.observer_ms_max = std::max(v_.stats_.observer_ms_max, ms);
  }
  CallbackTimer(const CallbackTimer&) = delete;
  CallbackTimer& operator=(const CallbackTimer&) = delete;

 private:
  LiveViewer& v_;
  Clock::time_point start_;
};

LiveViewer::LiveViewer(const LiveViewerOptions& options)
    : options_(options), server_(board_, load_assets(options.assets), options.server) {
  board_.set_greeting(sse_event("hello", nlohmann::json{{"version", std::string(kVersion)},
                                                        {"title", options_.title},
                                                        {"live", true},
                                                        {"groundtruth", options_.groundtruth.has_value()}}
                                             .dump()));
  encoder_ = std::thread([this] { encoder_loop(); });
}

LiveViewer::~LiveViewer() { stop(); }

void LiveViewer::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (encoder_.joinable()) encoder_.join();
  {
    std::lock_guard lock(dense_mutex_);
    dense_.reset();
  }
  server_.stop();
}

LiveViewerStats LiveViewer::stats() const {
  std::lock_guard lock(mutex_);
  LiveViewerStats s = stats_;
  s.frames_sent = board_.frames_sent();
  std::lock_guard dense(dense_mutex_);
  if (dense_) s.dense = dense_->stats();
  return s;
}

void LiveViewer::on_added(const Pipeline& slam) { slam_ = &slam; }

void LiveViewer::log(std::string_view event, const nlohmann::json& data) {
  {
    std::lock_guard lock(mutex_);
    log_.push_back(sse_event(event, data.dump()));
  }
  wake_.notify_one();
}

void LiveViewer::on_depth_registration(const DepthRegistrationEvent& e) {
  const CallbackTimer timer(*this);
  log("registration", {{"mode", e.mode}, {"found", e.found}, {"scale", e.scale}, {"du", e.du}, {"dv", e.dv},
                      {"baseline_x_m", e.baseline_x}});
}

void LiveViewer::on_detection(const DetectionEvent& e) {
  const CallbackTimer timer(*this);
  FrameView& v = building_.view;
  v.person_filter = true;
  v.have_detections = e.have_detections;
  v.box_age_s = e.box_age_s;
  v.people.clear();
  for (std::size_t i = 0; i < e.people.rects.size(); ++i)
    v.people.push_back(
        {e.people.rects[i], i < e.people.persons.size() ? e.people.persons[i].whole_m : 0.0f, e.depth_band_m});
  building_.person_dropped.clear();
  for (std::size_t i = 0; i < e.keypoints.size() && i < e.keep.size(); ++i)
    if (!e.keep[i]) building_.person_dropped.push_back(e.keypoints[i].pt);
}

void LiveViewer::on_keypoints(const KeypointsEvent& e) {
  const CallbackTimer timer(*this);
  building_.features = e.features;
  building_.fate = e.fate;
  building_.image = e.image;
}

void LiveViewer::on_frame(const FrameResult& r) {
  const CallbackTimer timer(*this);
  const auto now = Clock::now();
  if (last_frame_time_ != Clock::time_point{}) {
    const double dt = std::chrono::duration<double>(now - last_frame_time_).count();
    if (dt > 0) fps_ = fps_ == 0 ? 1.0 / dt : 0.9 * fps_ + 0.1 / dt;
  }
  last_frame_time_ = now;
  if (r.T_wc) live_.push_back({r.timestamp, *r.T_wc});

  FrameView& v = building_.view;
  v.index = r.index;
  v.timestamp = r.timestamp;
  v.state = r.state;
  v.keyframe = r.keyframe;
  v.new_segment = r.new_segment;
  v.keypoints = r.keypoints;
  v.inliers = r.inliers;
  v.depth_edge_rejected = r.depth_edge_rejected;
  v.timings = r.timings;
  v.fps = fps_;
  v.T_wc = r.T_wc;
  v.map_keyframes = r.map_keyframes;
  v.map_points = r.map_points;
  if (r.new_segment) log("segment", {{"index", r.index}, {"t", r.timestamp}});
  {
    std::lock_guard lock(mutex_);
    frame_ = std::move(building_);  // replaces a frame the encoder has not taken yet
    ++stats_.frames_seen;
  }
  building_ = PendingFrame{};
  wake_.notify_one();
  if (slam_ && slam_->dense_map()) {
    std::lock_guard lock(dense_mutex_);
    // Once, or again for a new map (the session was reset): a pointer compare otherwise.
    if (!dense_ || &dense_->map() != slam_->dense_map()) {
      if (dense_) dense_->clear();  // the old map's regions off the page
      dense_ = std::make_unique<DenseLayer>(slam_->shared_dense_map(), board_, options_.dense);
    }
  }
  if (board_.clients() > 0 && seconds_since(last_map_gather_) >= 1.0 / options_.map_rate) gather_map();
}

LiveViewer::PendingMap LiveViewer::snapshot(bool final) const {
  PendingMap m;
  m.keyframes = slam_->map().keyframes();
  m.points = slam_->map().map_points();
  m.live = live_;
  if (final) m.final_trajectory = slam_->camera_trajectory();
  m.final = final;
  return m;
}

void LiveViewer::gather_map() {
  if (!slam_) return;
  last_map_gather_ = Clock::now();
  PendingMap m = snapshot(false);
  {
    std::lock_guard lock(mutex_);
    map_ = std::move(m);
  }
  wake_.notify_one();
}

void LiveViewer::on_keyframe_mapped(const slam::KeyframeMapped& m) {
  const CallbackTimer timer(*this);
  if (!m.ba) return;
  log("alpha", {{"keyframe", m.keyframe_id},
                {"t", m.timestamp},
                {"alpha", m.ba->final_alpha},
                {"fitted", m.ba->fitted_alpha},
                {"refine", m.ba->refine_alpha},
                {"observations", m.ba->observations},
                {"outliers", m.ba->outliers}});
}

void LiveViewer::on_loop(const slam::LoopRecord& l) {
  const CallbackTimer timer(*this);
  log("loop", {{"query", l.query_keyframe},
               {"match", l.loop_keyframe},
               {"t", l.timestamp},
               {"inliers", l.inliers},
               {"correction_m", l.correction_m},
               {"correction_deg", l.correction_deg}});
}

void LiveViewer::on_relocalization(const RelocalizationEvent& e) {
  const CallbackTimer timer(*this);
  log("relocalization", {{"index", e.frame_index},
                         {"t", e.timestamp},
                         {"keyframe", e.relocalization.keyframe_id},
                         {"inliers", e.relocalization.inliers}});
}

void LiveViewer::on_finished() {  // after tracking: not counted as time taken from it
  // Encoded here, not on the encoder thread: once the caller has its final map it may destroy the pipeline, which
  // takes the keyframe graph apart.
  if (slam_) {
    std::string message = encode_map(snapshot(true));
    {
      std::lock_guard lock(mutex_);
      map_.reset();
    }
    std::lock_guard publish(map_publish_mutex_);
    board_.set_map(std::move(message));
    final_map_published_ = true;
  }
  {
    // The final dense map (finish() fused it again from the final poses), for browsers now and later.
    std::lock_guard lock(dense_mutex_);
    if (dense_) {
      dense_->stop();
      dense_->update();
    }
  }
  if (slam_) {
    const PipelineSummary s = slam_->summary();
    log("done", {{"frames", s.frames},
                 {"tracked", s.tracked},
                 {"keyframes", s.keyframes},
                 {"map_points", s.map_points},
                 {"segments", s.segments},
                 {"relocalizations", s.relocalizations}});
  }
}

void LiveViewer::encoder_loop() {
  auto last_frame = Clock::now() - std::chrono::hours(1);
  auto last_map = last_frame;
  for (;;) {
    std::optional<PendingFrame> frame;
    std::optional<PendingMap> map;
    std::vector<std::string> logged;
    {
      std::unique_lock lock(mutex_);
      // Without a browser a pending frame is no work: wake for it only once one is connected (checked every 50 ms).
      wake_.wait_for(lock, std::chrono::milliseconds(50),
                     [&] { return stopping_ || !log_.empty() || map_ || (frame_ && board_.clients() > 0); });
      if (stopping_) return;
      logged.swap(log_);
      // Frames wait for a browser (the newest one is kept) and for their slot in the rate.
      if (frame_ && board_.clients() > 0 && seconds_since(last_frame) >= 1.0 / options_.max_frame_rate)
        frame = std::exchange(frame_, std::nullopt);
      if (map_ && seconds_since(last_map) >= 1.0 / options_.map_rate) map = std::exchange(map_, std::nullopt);
    }
    for (std::string& e : logged) board_.append(std::move(e));
    if (map) {
      std::string message = encode_map(*map);
      std::lock_guard publish(map_publish_mutex_);
      if (!final_map_published_) board_.set_map(std::move(message));
      last_map = Clock::now();
      std::lock_guard lock(mutex_);
      ++stats_.maps_encoded;
    }
    if (frame) {
      board_.set_frame(encode_frame(*frame));
      last_frame = Clock::now();
      std::lock_guard lock(mutex_);
      ++stats_.frames_encoded;
    }
    if (!frame && !map && logged.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

std::string LiveViewer::encode_frame(PendingFrame& f) const {
  if (f.features) {
    const std::vector<cv::Point2f> px = image_pixels(*f.features);
    f.view.marks.reserve(px.size() + f.person_dropped.size());
    for (std::size_t i = 0; i < px.size(); ++i) {
      std::uint8_t mark = static_cast<std::uint8_t>(KeypointMark::Unmatched);
      if (i < f.fate.size() && f.fate[i] == slam::KeypointFate::Inlier)
        mark = static_cast<std::uint8_t>(KeypointMark::Inlier);
      if (i < f.fate.size() && f.fate[i] == slam::KeypointFate::Outlier)
        mark = static_cast<std::uint8_t>(KeypointMark::Outlier);
      if (i < f.features->on_depth_edge.size() && f.features->on_depth_edge[i]) mark |= kDepthEdgeBit;
      f.view.marks.push_back({px[i].x, px[i].y, mark});
    }
  }
  for (const cv::Point2f& p : f.person_dropped)
    f.view.marks.push_back({p.x, p.y, static_cast<std::uint8_t>(KeypointMark::PersonDropped)});
  return sse_event("frame", frame_message(f.view, f.image).dump());
}

std::string LiveViewer::encode_map(const PendingMap& m) const {
  MapView v;
  v.final = m.final;
  for (const slam::KeyFramePtr& kf : m.keyframes) {
    if (kf->is_bad()) continue;
    v.keyframes.push_back({kf->id(), kf->pose().inverse()});
    for (const auto& [other, weight] : kf->connections())
      if (weight >= kDrawnCovisibility && other->id() > kf->id() && !other->is_bad())
        v.covisibility.emplace_back(kf->id(), other->id());
    if (const auto parent = kf->parent()) v.spanning_tree.emplace_back(kf->id(), parent->id());
  }
  v.points.reserve(m.points.size());
  for (const slam::MapPointPtr& p : m.points) {
    if (p->is_bad()) continue;
    const int flagged = p->flagged(), found = p->found();
    v.points.push_back({p->position().cast<float>(), static_cast<float>(p->first_keyframe_id()),
                        static_cast<float>(flagged) / static_cast<float>(std::max(1, flagged + found))});
  }
  v.live = positions(m.live);
  v.final_trajectory = positions(m.final_trajectory);
  if (options_.groundtruth)
    v.groundtruth = groundtruth_in_map_frame(*options_.groundtruth, m.final ? m.final_trajectory : m.live);
  return sse_event("map", map_message(v).dump());
}

}  // namespace varslam::viewer
