#pragma once
// Statistics of the sensor that do not depend on the scene (issue #33): residuals after pose optimisation, track
// lengths of map points, depth consistency between keyframes, share of keypoints with depth. MetricsRecorder
// writes them into metrics.json ("sensor"); `varslam sensor-stats` puts the sections of several runs side by side,
// so a synthetic sensor can be compared with a real one.
#include <Eigen/Geometry>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <random>
#include <vector>

#include "core/camera.hpp"
#include "core/trajectory.hpp"

namespace varslam::slam {
class Map;
}

namespace varslam::run {

/// Nearest-rank percentile q in [0, 1] of a sample; 0 when empty.
double percentile(std::vector<double> v, double q);

/// A keyframe's depth kept for the depth-consistency check after the run: every kDepthStep-th pixel in both
/// directions, in millimetres (CV_16UC1, 0 = none), so a long run keeps ~150 kB a keyframe instead of 1.2 MB.
struct KeyframeDepth {
  static constexpr int kDepthStep = 2;
  double timestamp = 0;
  bool new_segment = false;  // first keyframe of a new map segment: not comparable with the keyframe before
  cv::Mat depth_mm;
};
KeyframeDepth keep_keyframe_depth(double timestamp, bool new_segment, const cv::Mat& depth_m);

/// |z_warped - z_b| / z_b for the depth of `a` warped into `b` (camera-to-world poses): every kSampleStep-th
/// full-resolution pixel of `a` with depth is back-projected, moved into b and compared with b's depth at the
/// nearest kept pixel (at most one full-resolution pixel away), where b has depth. Lens distortion is ignored,
/// as the dense map does. Occlusions are counted too (a surface b sees in front of a's point): they land in the
/// upper tail, which is why the median and p90 are reported rather than a mean.
inline constexpr int kSampleStep = 4;
std::vector<double> depth_disagreement(const KeyframeDepth& a, const Eigen::Isometry3d& T_wa, const KeyframeDepth& b,
                                       const Eigen::Isometry3d& T_wb, const PinholeCamera& cam);

/// depth_disagreement() over every keyframe and the one before it, at their final poses (`final_poses`, looked up
/// by timestamp); pairs across a new map segment or with a keyframe missing from `final_poses` are skipped.
struct DepthConsistency {
  std::vector<double> disagreement;
  std::size_t pairs = 0;
};
DepthConsistency depth_consistency(const std::vector<KeyframeDepth>& keyframes, const Trajectory& final_poses,
                                   const PinholeCamera& cam);

/// Drift that neighbouring keyframes cannot show: keyframe pairs at least `min_gap_s` apart whose views overlap
/// (optical axes within `max_angle_deg`, centres within `max_distance_m`, and at least `min_overlap` of a's
/// samples with depth on the same surface in b, |dz| / z below `same_surface`), at most `max_pairs` of them spread
/// evenly over the candidates. Per pair, the median |dz| / z of the samples on the same surface.
struct DistantPairs {
  double min_gap_s = 5.0;
  double max_angle_deg = 60.0;
  double max_distance_m = 3.0;
  double same_surface = 0.05;
  double min_overlap = 0.3;
  std::size_t max_pairs = 400;
};
struct LongRangeConsistency {
  std::vector<double> pair_median;  // one per compared pair
  std::size_t candidates = 0;       // pairs that passed the gap and pose checks, before the cap
};
LongRangeConsistency long_range_consistency(const std::vector<KeyframeDepth>& keyframes, const Trajectory& poses,
                                            const PinholeCamera& cam, const DistantPairs& rule = {});
/// The metrics.json form: mean and median of the pair medians, pairs compared, candidates, the gap.
nlohmann::json long_range_section(const LongRangeConsistency& c, const DistantPairs& rule = {});

/// Keyframes observing each map point of the map (points not bad).
std::vector<double> track_lengths(const slam::Map& map);

/// The sensor section of metrics.json from the pooled samples (see MetricsRecorder::metrics for what each holds).
/// A uniform sample of at most `capacity` values of a stream (reservoir sampling, fixed seed: the same stream gives
/// the same sample), so a run of hours keeps a bounded memory for its residual percentiles.
class SampleReservoir {
 public:
  explicit SampleReservoir(std::size_t capacity = 200000) : capacity_(capacity) {}
  void add(double v) {
    ++seen_;
    if (values_.size() < capacity_) {
      values_.push_back(v);
      return;
    }
    const std::size_t j = static_cast<std::size_t>(rng_() % seen_);
    if (j < capacity_) values_[j] = v;
  }
  const std::vector<double>& values() const { return values_; }
  std::size_t seen() const { return seen_; }

 private:
  std::size_t capacity_, seen_ = 0;
  std::vector<double> values_;
  std::mt19937_64 rng_{20261203};
};

struct SensorSamples {
  std::vector<double> depth_share;                               // per frame
  std::vector<double> reprojection_px;                           // pooled over the tracked frames' inliers
  std::vector<double> depth_residual_m, depth_residual_over_z2;  // pooled over the inliers with depth
  std::size_t residual_frames = 0;                               // frames that gave residuals
  // Observations behind the residuals (the vectors above may be a uniform sample of them); 0: their sizes.
  std::size_t reprojection_observations = 0, depth_observations = 0;
  std::vector<double> track_length;                              // per map point
  DepthConsistency consistency;
  LongRangeConsistency long_range;
};
nlohmann::json sensor_section(const SensorSamples& s);

/// The "sensor" section of RUN_DIR/metrics.json; InputError naming the folder or the file when it is missing,
/// unreadable or has no such section.
nlohmann::json read_sensor_section(const std::filesystem::path& run_dir);

/// A markdown table, one row per statistic and one column per run (`names[i]` heads the column of sections[i]).
std::string sensor_table_markdown(const std::vector<std::string>& names, const std::vector<nlohmann::json>& sections);

}  // namespace varslam::run
