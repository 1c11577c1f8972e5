#pragma once
// The observer behind metrics.json: per-stage timings (median, p95), keypoint counts, the alpha of every Local
// BA, each closed loop, the person detector's latency and box age, depth registration. Adding a metric means
// recording it here from an event and writing it in metrics().
#include <nlohmann/json.hpp>
#include <vector>

#include "pipeline/slam.hpp"
#include "run/sensor_stats.hpp"

namespace varslam::run {

/// Median and 95th percentile (nearest rank) of a sample, {0, 0} when empty.
std::pair<double, double> median_p95(std::vector<double> v);

class MetricsRecorder final : public Observer {
 public:
  /// Time the dataset loop waited for the frame (decoding runs ahead on its own thread).
  void add_load_ms(double ms) { load_ms_.push_back(ms); }
  /// Real time: from the frame's arrival (its due time when paced, else the call) to its pose.
  void add_latency_ms(double ms) { latency_ms_.push_back(ms); }
  /// Real time, paced: a newer frame had already arrived when tracking was free for this one; `dropped`: it was
  /// not tracked (--drop-late), else it was tracked late.
  void add_late_frame(bool dropped) { ++(dropped ? dropped_frames_ : late_frames_); }

  void on_depth_registration(const DepthRegistrationEvent& e) override;
  void on_frame(const FrameResult& f) override;
  void on_keyframe(const KeyframeEvent& k) override;
  void on_detection(const DetectionEvent& d) override;
  void on_keyframe_mapped(const slam::KeyframeMapped& m) override;
  void on_loop_search(const slam::LoopSearch& s) override { loop_search_ms_.push_back(s.ms); }
  void on_loop(const slam::LoopRecord& l) override { loops_.push_back(l); }

  /// The metrics of the run so far; `slam` gives the facts kept by the pipeline (map size, segments, kernels).
  nlohmann::json metrics(const Pipeline& slam) const;
  const std::vector<double>& frame_timestamps() const { return stamps_; }
  /// The long-range depth consistency of the run's keyframes at another trajectory's poses (the ground truth's: a
  /// reference for what the sensor's depth allows), each keyframe at that trajectory's pose nearest in time.
  nlohmann::json long_range_consistency_at(const Trajectory& poses, const PinholeCamera& cam) const;
  std::size_t frames() const { return stamps_.size(); }
  std::size_t tracked() const { return tracked_; }
  /// Medians over the frames: ORB keypoints, and the share of them with a valid depth (what a failed run lacked).
  double median_keypoints() const { return median_p95(keypoints_).first; }
  double median_depth_share() const { return median_p95(depth_share_).first; }

 private:
  nlohmann::json registration_ = {{"mode", "off"}};
  std::vector<double> stamps_, load_ms_, extract_, filter_, match_, pose_, track_, edge_rejected_, keypoints_,
      depth_share_;
  std::size_t tracked_ = 0;
  // The sensor section (run/sensor_stats.hpp): residuals pooled over the run, keyframe depth for after it.
  SampleReservoir reprojection_px_, depth_residual_m_, depth_residual_over_z2_;
  static constexpr std::size_t kKeyframesWithDepth = 300;  // about 45 MB; pairs after these are not compared
  std::size_t residual_frames_ = 0;
  std::vector<KeyframeDepth> keyframe_depth_;
  nlohmann::json sensor(const Pipeline& slam) const;
  std::vector<double> keyframe_ms_, ba_ms_, loop_search_ms_;
  nlohmann::json ba_ = nlohmann::json::array();
  int triangulated_ = 0, culled_points_ = 0, culled_keyframes_ = 0;
  std::vector<slam::LoopRecord> loops_;
  bool semantic_ran_ = false;
  long frames_without_boxes_ = 0;
  double fresh_box_share() const;
  std::vector<double> box_age_ms_, detector_latency_ms_, dropped_;
  std::vector<double> latency_ms_, mapping_queue_;
  long dropped_frames_ = 0, late_frames_ = 0, ba_skipped_ = 0, ba_cut_short_ = 0, keyframes_mapped_ = 0;
};

}  // namespace varslam::run
