#include "run/metrics_recorder.hpp"

#include <algorithm>
#include <cmath>

#include "eval/association.hpp"

namespace varslam::run {
namespace {

nlohmann::json timing_json(const std::vector<double>& v) {
  const auto [med, p95] = median_p95(v);
  return {{"median_ms", med}, {"p95_ms", p95}, {"count", v.size()}};
}

nlohmann::json count_json(const std::vector<double>& v) {
  const auto [med, p95] = median_p95(v);
  return {{"median", med}, {"p95", p95}, {"frames", v.size()}};
}

}  // namespace

std::pair<double, double> median_p95(std::vector<double> v) {
  if (v.empty()) return {0.0, 0.0};
  std::sort(v.begin(), v.end());
  const double med = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  const std::size_t k = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(v.size()))) - 1;
  return {med, v[std::min(k, v.size() - 1)]};
}

void MetricsRecorder::on_depth_registration(const DepthRegistrationEvent& e) {
  if (e.mode != "auto") {
    registration_ = {{"mode", e.mode}};
    return;
  }
  registration_ = {{"mode", "auto"}, {"found", e.found}, {"scale", e.scale}, {"du", e.du}, {"dv", e.dv},
                   {"baseline_x_m", e.baseline_x},
                   {"score", e.score}, {"identity_score", e.identity_score}, {"frames", e.frames}, {"ms", e.ms}};
  if (e.colour_camera)
    registration_["colour_camera"] = {{"fx", e.colour_camera->fx}, {"fy", e.colour_camera->fy},
                                      {"cx", e.colour_camera->cx}, {"cy", e.colour_camera->cy}};
}

void MetricsRecorder::on_frame(const FrameResult& f) {
  stamps_.push_back(f.timestamp);
  tracked_ += f.state == TrackState::Ok;
  extract_.push_back(f.timings.extract_ms);
  filter_.push_back(f.timings.filter_ms);
  match_.push_back(f.timings.match_ms);
  pose_.push_back(f.timings.pose_ms);
  track_.push_back(f.timings.track_ms);
  edge_rejected_.push_back(f.depth_edge_rejected);
  keypoints_.push_back(f.keypoints);
  depth_share_.push_back(f.keypoints > 0 ? static_cast<double>(f.keypoints_with_depth) / f.keypoints : 0.0);
  mapping_queue_.push_back(static_cast<double>(f.mapping_queue));
  const slam::PoseResiduals& r = f.residuals;
  residual_frames_ += !r.reprojection_px.empty();
  for (const double px : r.reprojection_px) reprojection_px_.add(px);
  for (std::size_t i = 0; i < r.depth_m.size(); ++i) {
    const double z = r.measured_depth_m[i];
    depth_residual_m_.add(r.depth_m[i]);
    // Kinect-class depth noise grows with z^2: normalised, near and far observations compare.
    depth_residual_over_z2_.add(r.depth_m[i] / (z * z));
  }
}

// Only a subsampled copy is kept; the comparison needs the final poses, so it waits for metrics().
void MetricsRecorder::on_keyframe(const KeyframeEvent& k) {
  if (keyframe_depth_.size() < kKeyframesWithDepth)
    keyframe_depth_.push_back(keep_keyframe_depth(k.timestamp, k.new_segment, k.depth));
}

// Residuals pooled over all inliers of all tracked frames (not per-frame medians): frames with many inliers weigh
// more, as they do in the pose. Track lengths and depth consistency come from the final map and trajectory.
nlohmann::json MetricsRecorder::sensor(const Pipeline& slam) const {
  SensorSamples s;
  s.depth_share = depth_share_;
  s.reprojection_px = reprojection_px_.values();
  s.depth_residual_m = depth_residual_m_.values();
  s.depth_residual_over_z2 = depth_residual_over_z2_.values();
  s.residual_frames = residual_frames_;
  s.reprojection_observations = reprojection_px_.seen();
  s.depth_observations = depth_residual_m_.seen();
  s.track_length = track_lengths(slam.map());
  s.consistency = depth_consistency(keyframe_depth_, slam.camera_trajectory(), slam.settings().camera);
  s.long_range = long_range_consistency(keyframe_depth_, slam.camera_trajectory(), slam.settings().camera);
  return sensor_section(s);
}

nlohmann::json MetricsRecorder::long_range_consistency_at(const Trajectory& poses, const PinholeCamera& cam) const {
  Trajectory at;
  if (!poses.empty()) {
    Trajectory sorted = poses;
    std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
    std::vector<double> stamps;
    for (const StampedPose& p : sorted) stamps.push_back(p.timestamp);
    for (const KeyframeDepth& k : keyframe_depth_) {
      const StampedPose& p = sorted[nearest_timestamp_index(stamps, k.timestamp)];
      if (std::abs(p.timestamp - k.timestamp) < AssociationOptions{}.max_difference)
        at.push_back({k.timestamp, p.T_wc});
    }
  }
  return long_range_section(long_range_consistency(keyframe_depth_, at, cam));
}

void MetricsRecorder::on_detection(const DetectionEvent& d) {
  semantic_ran_ = true;
  if (d.have_detections) {
    box_age_ms_.push_back(1000.0 * d.box_age_s);
    detector_latency_ms_.push_back(1000.0 * d.detector_latency_s);
  } else {
    ++frames_without_boxes_;
  }
  dropped_.push_back(d.stats.dropped);
}

// Frames whose boxes come from an image at most two frames older at 30 Hz (timestamps jitter by a few ms), out
// of all frames the person filter saw, counting those before the first detection as not fresh.
double MetricsRecorder::fresh_box_share() const {
  constexpr double kFreshMs = 70.0;
  const std::size_t frames = box_age_ms_.size() + static_cast<std::size_t>(frames_without_boxes_);
  if (frames == 0) return 0.0;
  const auto fresh = std::count_if(box_age_ms_.begin(), box_age_ms_.end(), [](double ms) { return ms <= kFreshMs; });
  return static_cast<double>(fresh) / static_cast<double>(frames);
}

void MetricsRecorder::on_keyframe_mapped(const slam::KeyframeMapped& m) {
  keyframe_ms_.push_back(m.ms);
  ++keyframes_mapped_;
  ba_skipped_ += m.ba_skipped;
  ba_cut_short_ += m.ba && m.ba->cut_short;
  triangulated_ += m.triangulated_points;
  culled_points_ += m.culled_points;
  culled_keyframes_ += m.culled_keyframes;
  if (!m.ba) return;
  const slam::BaRecord& b = *m.ba;
  ba_ms_.push_back(b.ms);
  ba_.push_back({{"keyframe", b.keyframe_id}, {"timestamp", b.timestamp}, {"keyframes", b.keyframes},
                 {"fixed_keyframes", b.fixed_keyframes}, {"points", b.points}, {"observations", b.observations},
                 {"outliers", b.outliers}, {"alpha_per_iteration", b.alpha_per_iteration},
                 {"final_alpha", b.final_alpha}, {"fitted_alpha", b.fitted_alpha}, {"refine_alpha", b.refine_alpha},
                 {"cut_short", b.cut_short}, {"ms", b.ms}});
}

nlohmann::json MetricsRecorder::metrics(const Pipeline& slam) const {
  const PipelineSummary s = slam.summary();
  nlohmann::json m;
  m["mode"] = slam.mode() == RunMode::Deterministic ? "deterministic" : "realtime";
  m["frames"] = frames();
  m["tracked_frames"] = tracked_;
  m["lost_frames"] = frames() - tracked_;
  m["tracked_share"] = frames() ? static_cast<double>(tracked_) / static_cast<double>(frames()) : 0.0;
  m["map_segments"] = s.segments;
  m["relocalizations"] = s.relocalizations;
  m["placed_back_frames"] = s.placed_back;
  m["near_mover_solves"] = s.near_mover_solves;
  m["keyframes"] = s.keyframes;
  m["map_points"] = s.map_points;
  m["triangulated_points"] = triangulated_;
  m["culled_points"] = culled_points_;
  m["culled_keyframes"] = culled_keyframes_;
  m["depth_registration"] = registration_;
  m["kernels"] = {{"tracking", slam::kernel_name(slam.config().tracking.kernel.type)},
                  {"mapping", slam::kernel_name(slam.config().mapping.kernel.type)}};
  m["timings"] = {{"load", timing_json(load_ms_)},       {"extract", timing_json(extract_)},
                  {"filter", timing_json(filter_)},      {"match", timing_json(match_)},
                  {"pose_optimization", timing_json(pose_)}, {"tracking", timing_json(track_)},
                  {"keyframe_processing", timing_json(keyframe_ms_)}, {"local_ba", timing_json(ba_ms_)},
                  {"loop_detection", timing_json(loop_search_ms_)}};
  m["local_ba"] = ba_;
  if (slam.mode() == RunMode::RealTime) {
    const auto queue = median_p95(mapping_queue_);
    m["realtime"] = {
        {"dropped_frames", dropped_frames_},
        {"late_frames", late_frames_},
        {"latency", timing_json(latency_ms_)},
        {"mapping_queue", {{"median", queue.first}, {"p95", queue.second},
                           {"max", mapping_queue_.empty() ? 0.0 : *std::max_element(mapping_queue_.begin(), mapping_queue_.end())}}},
        {"keyframes_mapped", keyframes_mapped_},
        {"local_ba_skipped", ba_skipped_},
        {"local_ba_cut_short", ba_cut_short_}};
  }
  nlohmann::json loops = nlohmann::json::array();
  for (const slam::LoopRecord& l : loops_)
    loops.push_back({{"keyframe", l.query_keyframe}, {"loop_keyframe", l.loop_keyframe}, {"timestamp", l.timestamp},
                     {"place_score", l.score}, {"ransac_inliers", l.ransac_inliers}, {"inliers", l.inliers},
                     {"fused_points", l.fused_points}, {"correction_m", l.correction_m},
                     {"correction_deg", l.correction_deg}, {"pose_graph_ms", l.pose_graph_ms},
                     {"global_ba_ms", l.global_ba_ms}, {"total_ms", l.total_ms}});
  m["loops"] = loops;
  m["keypoints_per_frame"] = count_json(keypoints_);
  m["depth_edge_rejected_per_frame"] = count_json(edge_rejected_);
  m["sensor"] = sensor(slam);
  if (s.detector != "none" || semantic_ran_) {
    m["semantic"] = {{"detector", s.detector}, {"detector_runs", s.detector_runs},
                     {"asynchronous", s.detector_asynchronous}, {"frames_without_boxes", frames_without_boxes_},
                     {"box_age", timing_json(box_age_ms_)}, {"fresh_box_share", fresh_box_share()},
                     {"detector_latency", timing_json(detector_latency_ms_)},
                     {"dropped_keypoints_per_frame", count_json(dropped_)}};
  }
  return m;
}

}  // namespace varslam::run
