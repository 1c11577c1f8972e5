#include "pipeline/slam.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <opencv2/imgproc.hpp>
#include <variant>

#include "core/elapsed.hpp"
#include "core/error.hpp"
#include "io/colour_registration.hpp"
#include "io/depth_image.hpp"
#include "io/settings_registry.hpp"
#include "dense/dense_mapper.hpp"
#include "semantic/dynamic_keypoint_masker.hpp"
#include "mapfile/map_file.hpp"

namespace varslam {
namespace {
using Clock = std::chrono::steady_clock;

// Raw depth from a separate depth camera (7-Scenes, raw Kinect v1) misfits the colour edges; the settings'
// intrinsics then describe the depth camera. When a zoom, shift and baseline clearly beat identity on the sample
// frames, depth is warped into the colour camera they imply. Registered data (TUM, Bonn, synthetic) comes out as
// identity.
DepthRegistrationEvent register_depth_if_needed(std::span<const RgbdFrame> samples, Settings& settings,
                                                slam::SlamConfig& cfg) {
  DepthRegistrationEvent ev;
  if (cfg.tracking.depth_rig) {
    ev.mode = "settings";
    return ev;
  }
  if (!cfg.tracking.estimate_registration) {
    ev.mode = "off";
    return ev;
  }
  ev.mode = "auto";
  const auto t0 = Clock::now();
  std::vector<cv::Mat> grays, depths;
  for (const RgbdFrame& f : samples) {
    if (f.gray.empty() || f.depth.empty()) continue;
    grays.push_back(f.gray);
    depths.push_back(f.depth);
  }
  ColourRegistrationSearch search;
  search.max_baseline_m = cfg.tracking.registration_max_baseline_m;
  const ColourRegistration reg = estimate_colour_registration(grays, depths, settings.camera, search);
  ev.found = reg.found;
  ev.scale = reg.scale;
  ev.du = reg.du;
  ev.dv = reg.dv;
  ev.baseline_x = reg.baseline_x;
  ev.score = reg.score;
  ev.identity_score = reg.identity_score;
  ev.frames = reg.frames;
  ev.ms = ms_since(t0);
  if (reg.found) {
    DepthCameraRig rig;
    rig.depth = settings.camera;
    rig.t_colour_depth = {reg.baseline_x, 0.0, 0.0};
    settings.camera = reg.colour_camera(rig.depth);
    cfg.tracking.depth_rig = rig;
    ev.colour_camera = settings.camera;
    spdlog::info("depth is not registered to colour (edge fit {:.2f} against {:.2f} as given): colour camera fx {:.1f} "
                 "cx {:.1f} cy {:.1f}, depth camera {:.1f} cm beside it, depth warped into it "
                 "(depth.registration: off to keep the images as they are)",
                 reg.score, reg.identity_score, settings.camera.fx, settings.camera.cx, settings.camera.cy,
                 100.0 * reg.baseline_x);
  }
  return ev;
}

// A frame of the caller's images, checked against the camera: gray for tracking, depth in metres.
RgbdFrame frame_from_images(const cv::Mat& bgr, const cv::Mat& depth, double timestamp, std::size_t index,
                            const Settings& settings) {
  const PinholeCamera& cam = settings.camera;
  const auto check_size = [&](const cv::Mat& m, const char* what) {
    if (m.cols != cam.width || m.rows != cam.height)
      throw InputError(fmt::format("Pipeline::track: {} image is {}x{}, the camera is {}x{}", what, m.cols, m.rows,
                                   cam.width, cam.height));
  };
  RgbdFrame f;
  f.index = index;
  f.timestamp = timestamp;
  if (bgr.empty()) throw InputError("Pipeline::track: empty colour image");
  check_size(bgr, "colour");
  if (bgr.type() == CV_8UC3) {
    f.bgr = bgr;
    cv::cvtColor(bgr, f.gray, cv::COLOR_BGR2GRAY);
  } else if (bgr.type() == CV_8UC1) {
    f.gray = bgr.clone();  // kept for box propagation: must not follow a capture buffer the caller reuses
    cv::cvtColor(bgr, f.bgr, cv::COLOR_GRAY2BGR);
  } else {
    throw InputError("Pipeline::track: the colour image must be CV_8UC3 (BGR) or CV_8UC1");
  }
  if (depth.empty()) throw InputError("Pipeline::track: empty depth image");
  check_size(depth, "depth");
  if (depth.type() == CV_16UC1) f.depth = depth_to_metres(depth, settings.depth_factor);
  else if (depth.type() == CV_32FC1) f.depth = depth;
  else throw InputError("Pipeline::track: the depth image must be CV_16UC1 (raw, depth.factor per metre) or CV_32FC1 (m)");
  return f;
}

// A decoded frame as the stages need it: gray and depth (metres) of the camera's size.
void check_frame(const RgbdFrame& f, const PinholeCamera& cam) {
  const auto fits = [&](const cv::Mat& m) { return m.cols == cam.width && m.rows == cam.height; };
  if (f.gray.empty() || f.gray.type() != CV_8UC1 || !fits(f.gray))
    throw InputError(fmt::format("Pipeline::track: frame {} needs a CV_8UC1 gray image of {}x{}", f.index, cam.width,
                                 cam.height));
  if (f.depth.empty() || f.depth.type() != CV_32FC1 || !fits(f.depth))
    throw InputError(fmt::format("Pipeline::track: frame {} needs a CV_32FC1 depth image in metres of {}x{}", f.index,
                                 cam.width, cam.height));
  if (!f.mover_mask.empty() && (f.mover_mask.type() != CV_8UC1 || !fits(f.mover_mask)))
    throw InputError(fmt::format("Pipeline::track: frame {}: the mover mask must be CV_8UC1 of {}x{} (it is {}x{}, "
                                 "type {})",
                                 f.index, cam.width, cam.height, f.mover_mask.cols, f.mover_mask.rows,
                                 f.mover_mask.type()));
}

// Settings built in code (not loaded) get the same whole-document check a file does.
const Settings& checked(const Settings& s) {
  check_settings_document(s.root, s.source, s.overrides);
  return s;
}

}  // namespace

// Records from the stages, any thread -> a queue the caller's thread empties.
class Pipeline::Relay final : public slam::SystemObserver {
 public:
  using Record = std::variant<slam::KeyframeMapped, slam::LoopSearch, slam::LoopRecord>;
  void on_keyframe_mapped(const slam::KeyframeMapped& r) override { push(r); }
  void on_loop_search(const slam::LoopSearch& r) override { push(r); }
  void on_loop_closed(const slam::LoopRecord& r) override { push(r); }
  std::vector<Record> take() {
    std::lock_guard lock(mutex_);
    return std::exchange(queue_, {});
  }

 private:
  void push(Record r) {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(r));
  }
  std::mutex mutex_;
  std::vector<Record> queue_;
};

Pipeline::Pipeline(const Settings& settings, PipelineOptions options)
    : settings_(checked(settings)),
      cfg_(slam::slam_config_from(settings)),
      options_(std::move(options)),
      semantic_(semantic::semantic_settings(settings)),
      relay_(std::make_unique<Relay>()) {
  dense_cfg_ = std::make_unique<dense::DenseConfig>(dense::dense_config(settings_));
  // Deterministic mode waits for each frame's detections, so results do not depend on timing.
  if (options_.mode == RunMode::Deterministic) semantic_.asynchronous = false;
  if (options_.detector) {
    // The caller's detector stays the caller's: the masker gets a forwarding one.
    struct Shared final : semantic::Detector {
      std::shared_ptr<semantic::Detector> d;
      explicit Shared(std::shared_ptr<semantic::Detector> det) : d(std::move(det)) {}
      Detections detect(const cv::Mat& bgr, double t) override { return d->detect(bgr, t); }
      std::string name() const override { return d->name(); }
    };
    masker_ = std::make_unique<semantic::DynamicKeypointMasker>(std::make_unique<Shared>(options_.detector), semantic_);
  } else if (semantic_.detector.source != "none") {
    masker_ = std::make_unique<semantic::DynamicKeypointMasker>(semantic_);
  }
}

Pipeline::~Pipeline() = default;

void Pipeline::add_observer(Observer& observer) {
  observers_.push_back(&observer);
  observer.on_added(*this);
}

void Pipeline::remove_observer(Observer& observer) {
  observers_.erase(std::remove(observers_.begin(), observers_.end(), &observer), observers_.end());
}

template <typename Event, typename Fn>
void Pipeline::emit(const Event& e, Fn fn) {
  const std::vector<Observer*> observers = observers_;  // an observer may add or remove observers meanwhile
  for (Observer* o : observers) (o->*fn)(e);
}

void Pipeline::calibrate_depth(std::span<const RgbdFrame> samples) {
  if (system_) throw std::logic_error("Pipeline::calibrate_depth: call it before the first frame");
  start(samples);
}

void Pipeline::start(std::span<const RgbdFrame> samples) {
  DepthRegistrationEvent reg = register_depth_if_needed(samples, settings_, cfg_);
  if (pending_map_ && (reg.found || !setting_given(settings_, "camera.fx"))) adopt_map_camera(reg);
  system_ = std::make_unique<slam::System>(cfg_, settings_.camera, settings_.close_depth_m(), options_.mode,
                                           relay_.get());
  if (pending_map_) {
    mapfile::check_map_compatible(pending_map_->fingerprint, settings_.camera, cfg_.orb.n_levels, cfg_.orb.scale_factor,
                               pending_map_file_.string());
    system_->adopt_map(*pending_map_);
    pending_map_.reset();
  }
  system_->set_localization_only(localization_only_);
  if (dense_cfg_->enabled)
    dense_ = std::make_shared<dense::DenseMapper>(*dense_cfg_, settings_.camera, options_.mode == RunMode::RealTime);
  if (pending_pose_hint_) system_->set_pose_hint(pending_pose_hint_->first, pending_pose_hint_->second);
  pending_pose_hint_.reset();
  if (masker_) install_person_filter();
  emit(reg, &Observer::on_depth_registration);
}

// A loaded map brings the colour camera it was built with, used unless the settings give intrinsics themselves: this
// session's own estimate from its few frames is compared and logged (two estimates of one camera differ by ~1 %).
void Pipeline::adopt_map_camera(DepthRegistrationEvent& reg) {
  const PinholeCamera& map = pending_map_->fingerprint.camera;
  PinholeCamera& now = settings_.camera;
  if (reg.found)
    spdlog::info("{}: the map's colour camera (fx {:.1f} fy {:.1f} cx {:.1f} cy {:.1f}) is used; this session "
                 "estimated fx {:.1f} fy {:.1f} cx {:.1f} cy {:.1f} from its own frames",
                 pending_map_file_.string(), map.fx, map.fy, map.cx, map.cy, now.fx, now.fy, now.cx, now.cy);
  else
    spdlog::info("{}: the map's colour camera (fx {:.1f} fy {:.1f} cx {:.1f} cy {:.1f}) is used (the settings give "
                 "no intrinsics)",
                 pending_map_file_.string(), map.fx, map.fy, map.cx, map.cy);
  now.fx = map.fx;
  now.fy = map.fy;
  now.cx = map.cx;
  now.cy = map.cy;
  if (reg.found) reg.colour_camera = now;
}

void Pipeline::install_person_filter() {
  system_->set_keypoint_filter([this](const RgbdFrame& f, const std::vector<cv::KeyPoint>& kps) {
    semantic::MaskResult r = masker_->process(f, kps);
    DetectionEvent d;
    d.source_index = f.index;
    d.timestamp = f.timestamp;
    d.have_detections = r.have_detections;
    d.box_age_s = r.staleness_s;
    d.detector_latency_s = r.detector_latency_s;
    d.propagated = r.propagated;
    d.boxes = std::move(r.boxes);
    d.stats = r.stats;
    d.people = std::move(r.people);
    d.depth_band_m = semantic_.filter.depth_band_m;
    d.keypoints = kps;
    d.keep = r.keep;
    d.bgr = f.bgr;
    detection_ = std::move(d);
    return r.keep;
  });
  if (semantic_.mask_extraction)
    system_->set_extraction_mask([this](const RgbdFrame& f) { return masker_->extraction_mask(f); });
}

std::function<void(RgbdFrame&)> Pipeline::frame_preparation() const {
  if (!system_ && wants_depth_samples())
    throw std::logic_error("Pipeline::frame_preparation: call calibrate_depth() first (depth.registration: auto)");
  if (!cfg_.tracking.depth_rig) return [](RgbdFrame& f) { f.depth_in_colour_frame = true; };
  return [rig = *cfg_.tracking.depth_rig, colour = settings_.camera](RgbdFrame& f) {
    if (f.depth_in_colour_frame) return;
    f.depth = register_depth_to_colour(f.depth, rig, colour);
    f.depth_in_colour_frame = true;
  };
}

FrameResult Pipeline::track(const cv::Mat& bgr, const cv::Mat& depth, double timestamp,
                            const std::optional<Detections>& boxes, const cv::Mat& mover_mask) {
  RgbdFrame frame = frame_from_images(bgr, depth, timestamp, frames_, settings_);
  frame.mover_mask = mover_mask;
  return track(frame, boxes);
}

FrameResult Pipeline::track(const RgbdFrame& input, const std::optional<Detections>& boxes) {
  if (finished_) throw std::logic_error("Pipeline::track after finish()");
  check_frame(input, settings_.camera);
  if (!system_) start(std::span<const RgbdFrame>(&input, 1));
  RgbdFrame frame = input;
  if (!frame.depth_in_colour_frame) frame_preparation()(frame);
  if (boxes) {
    if (!masker_) {  // no detector configured: the caller's boxes switch the person filter on
      semantic::DetectorConfig none = semantic_.detector;
      none.source = "none";
      masker_ = std::make_unique<semantic::DynamicKeypointMasker>(semantic::make_detector(none), semantic_);
      install_person_filter();
    }
    masker_->give_boxes(*boxes);
  }

  const slam::TrackOutcome out = system_->process(frame);
  if (masker_) masker_->give_boxes(std::nullopt);  // unused (no keypoints reached the filter): not for the next frame
  FrameResult r;
  r.index = frames_++;
  r.timestamp = frame.timestamp;
  r.state = out.state;
  r.keyframe = out.keyframe;
  r.keyframe_id = out.keyframe_id;
  r.new_segment = out.new_segment;
  r.keypoints = out.keypoints;
  r.keypoints_with_depth = out.keypoints_with_depth;
  r.inliers = out.inliers;
  r.depth_edge_rejected = out.depth_edge_rejected;
  r.timings = out.timings;
  r.residuals = out.residuals;
  r.T_wc = out.live_T_wc;
  r.map_keyframes = system_->map().num_keyframes();
  r.map_points = system_->map().num_map_points();
  r.mapping_queue = system_->mapping_queue();
  if (out.live_T_wc) {
    live_.push_back({frame.timestamp, *out.live_T_wc});
    ++tracked_;
  }

  if (dense_ && out.new_keyframe) give_dense_keyframe(frame, out);
  if (cfg_.loop.final_dense_refine && out.new_keyframe) keep_keyframe_depth(frame, out);
  if (detection_) {
    detection_->index = r.index;
    emit(*std::exchange(detection_, std::nullopt), &Observer::on_detection);
  }
  if (!observers_.empty() && out.features)
    emit(KeypointsEvent{r.index, r.timestamp, out.features, out.keypoint_fate, frame.bgr.empty() ? frame.gray : frame.bgr},
         &Observer::on_keypoints);
  if (out.relocalized) emit(RelocalizationEvent{r.index, r.timestamp, *out.relocalized}, &Observer::on_relocalization);
  if (out.keyframe && out.live_T_wc)
    emit(KeyframeEvent{out.keyframe_id, r.index, r.timestamp, *out.live_T_wc, out.new_segment, frame.depth},
         &Observer::on_keyframe);
  emit(r, &Observer::on_frame);
  deliver_queued();
  return r;
}

// The dense map gets the keyframe's images and what moved in them; the mask itself is made on the dense map's thread.
void Pipeline::give_dense_keyframe(const RgbdFrame& frame, const slam::TrackOutcome& out) {
  dense::DenseKeyframe kf;
  kf.id = out.keyframe_id;
  kf.timestamp = frame.timestamp;
  kf.depth = frame.depth;
  kf.bgr = frame.bgr;
  kf.pose = [k = out.new_keyframe] { return Eigen::Isometry3d(k->resolved_pose().inverse()); };
  kf.movers = mover_inputs(frame, out);
  dense_->add(std::move(kf));
}

// The keyframe keeps its depth for the dense refinement when the run ends, without the movers someone named (person
// boxes, the caller's mask). Not without the near mover tracking follows: in real scenes it also follows static
// near surfaces for seconds (BENCHMARKS.md), and hiding those costs the alignments more than a mover in view does.
void Pipeline::keep_keyframe_depth(const RgbdFrame& frame, const slam::TrackOutcome& out) {
  const dense::MoverMaskInputs named = named_mover_inputs(frame);
  const cv::Mat mask = named.names_nothing() ? cv::Mat() : dense::mover_mask(frame.depth, named);
  out.new_keyframe->set_depth_sample(slam::DepthSample::of(frame.depth, mask));
}

// The movers someone named (dense/mover_mask.hpp): the person filter's people and the caller's mask.
dense::MoverMaskInputs Pipeline::named_mover_inputs(const RgbdFrame& frame) const {
  dense::MoverMaskInputs m;
  m.point_radius_px = dense_cfg_->point_radius_px;
  m.margin_px = dense_cfg_->margin_px;
  m.caller_mask = frame.mover_mask;
  if (detection_) {
    const semantic::PersonRegions& p = detection_->people;
    for (std::size_t i = 0; i < p.rects.size(); ++i) {
      const semantic::PersonDepth& d = p.persons[i];
      m.people.push_back({p.rects[i], d.whole_m, detection_->depth_band_m});
      if (d.own_part_m > 0) m.people.push_back({p.rects[i], d.own_part_m, detection_->depth_band_m});
    }
  }
  return m;
}

// What the keyframe shows that moved: the named movers, the near mover tracking follows and the keypoints it flagged.
dense::MoverMaskInputs Pipeline::mover_inputs(const RgbdFrame& frame, const slam::TrackOutcome& out) const {
  dense::MoverMaskInputs m = named_mover_inputs(frame);
  if (out.mover) {
    const Eigen::AlignedBox2f& r = out.mover->region;
    if (!r.isEmpty())
      m.near_movers.push_back({cv::Rect2f(r.min().x(), r.min().y(), r.sizes().x(), r.sizes().y()),
                               out.mover->near_depth, out.mover->far_depth, out.mover->depth_margin});
  }
  if (out.features) {
    const slam::FrameFeatures& F = *out.features;
    for (std::size_t i = 0; i < F.size(); ++i) {
      const bool on_mover = i < out.on_mover.size() && out.on_mover[i];
      const bool outlier = i < out.keypoint_fate.size() && out.keypoint_fate[i] == slam::KeypointFate::Outlier;
      if (on_mover || outlier) m.moving_points.push_back({F.keypoints[i].pt, F.has_depth(i) ? F.depth[i] : 0.0f});
    }
  }
  return m;
}

void Pipeline::deliver_queued() {
  for (const Relay::Record& rec : relay_->take()) {
    if (const auto* m = std::get_if<slam::KeyframeMapped>(&rec)) emit(*m, &Observer::on_keyframe_mapped);
    else if (const auto* s = std::get_if<slam::LoopSearch>(&rec)) emit(*s, &Observer::on_loop_search);
    else if (const auto* l = std::get_if<slam::LoopRecord>(&rec)) emit(*l, &Observer::on_loop);
  }
}

void Pipeline::finish() {
  if (finished_) return;
  finished_ = true;
  try {
    if (system_) system_->finish();
  } catch (...) {
    deliver_queued();  // what mapping did before the error still reaches the observers
    throw;
  }
  deliver_queued();
  if (dense_) dense_->finish();  // from the final keyframe poses
  const std::vector<Observer*> observers = observers_;
  for (Observer* o : observers) o->on_finished();
}

void Pipeline::load_map(const std::filesystem::path& file) {
  if (system_) throw std::logic_error("Pipeline::load_map after the first frame");
  mapfile::SavedMap m = mapfile::load_map_file(file);
  // The colour camera may still change (depth registration is estimated at start()): intrinsics are checked then,
  // size and pyramid now.
  PinholeCamera now = settings_.camera;
  if (wants_depth_samples() || !setting_given(settings_, "camera.fx")) {
    now.fx = m.fingerprint.camera.fx;
    now.fy = m.fingerprint.camera.fy;
    now.cx = m.fingerprint.camera.cx;
    now.cy = m.fingerprint.camera.cy;
  }
  mapfile::check_map_compatible(m.fingerprint, now, cfg_.orb.n_levels, cfg_.orb.scale_factor, file.string());
  loaded_alignment_ = m.groundtruth_alignment;
  pending_map_file_ = file;
  pending_map_ = std::move(m);
}

void Pipeline::set_localization_only(bool on) {
  if (on && !system_ && !pending_map_)
    throw std::logic_error("Pipeline::set_localization_only: there is no map to localize in (load_map() first)");
  localization_only_ = on;
  if (system_) system_->set_localization_only(on);
}

void Pipeline::relocalize_near(const Eigen::Isometry3d& T_wc, double radius_m) {
  if (system_) system_->set_pose_hint(T_wc, radius_m);
  else pending_pose_hint_ = {T_wc, radius_m};
}

void Pipeline::save_map(const std::filesystem::path& file, const std::optional<Eigen::Isometry3d>& groundtruth_alignment) {
  mapfile::save_map_file(map_to_save(file, groundtruth_alignment), file);
}

slam::SavedMap Pipeline::map_to_save(const std::filesystem::path& file,
                                     const std::optional<Eigen::Isometry3d>& groundtruth_alignment) {
  if (!system_) throw InputError(fmt::format("{}: no map to save (no frame was tracked)", file.string()));
  mapfile::MapFingerprint fp;
  fp.camera = settings_.camera;
  fp.n_levels = cfg_.orb.n_levels;
  fp.scale_factor = cfg_.orb.scale_factor;
  fp.close_depth = settings_.close_depth_m();
  fp.disparity_weight = cfg_.tracking.disparity_weight;
  fp.settings_yaml = settings_yaml(settings_);
  fp.created_by = "varslam " + std::string(kVersion);
  slam::SavedMap m = system_->snapshot_now(std::move(fp));
  if (m.keyframes.empty()) throw InputError(fmt::format("{}: no map to save (no keyframe)", file.string()));
  m.groundtruth_alignment = groundtruth_alignment;
  return m;
}

Trajectory Pipeline::camera_trajectory(int* repaired) const {
  if (repaired) *repaired = 0;
  return system_ ? system_->camera_trajectory(false, repaired) : Trajectory{};
}

Trajectory Pipeline::keyframe_trajectory() const { return system_ ? system_->keyframe_trajectory() : Trajectory{}; }

const slam::Map& Pipeline::map() const { return system_ ? system_->map() : empty_map_; }

PipelineSummary Pipeline::summary() const {
  PipelineSummary s;
  s.frames = frames_;
  s.tracked = tracked_;
  if (system_) {
    s.keyframes = system_->map().num_keyframes();
    s.map_points = system_->map().num_map_points();
    s.segments = system_->tracker().segments();
    s.relocalizations = system_->tracker().relocalizations();
    s.placed_back = system_->tracker().placed_back_frames();
    s.near_mover_solves = system_->tracker().near_mover_frames();
  }
  s.detector = masker_ ? masker_->detector_name() : "none";
  s.detector_runs = masker_ ? masker_->detector_runs() : 0;
  s.detector_asynchronous = masker_ && semantic_.asynchronous;
  return s;
}

}  // namespace varslam
