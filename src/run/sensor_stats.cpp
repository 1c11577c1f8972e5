#include "run/sensor_stats.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>

#include "core/error.hpp"
#include "core/geometry.hpp"
#include "slam/dense_alignment.hpp"
#include "slam/map.hpp"

namespace varslam::run {
namespace {

namespace fs = std::filesystem;

double mean(const std::vector<double>& v) {
  return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

// Depth of b at the kept pixel nearest to full-resolution (u, v), metres; 0 outside or without depth.
double kept_depth_at(const KeyframeDepth& b, double u, double v) {
  constexpr int s = KeyframeDepth::kDepthStep;
  const int c = static_cast<int>(std::lround(u / s)), r = static_cast<int>(std::lround(v / s));
  if (c < 0 || r < 0 || c >= b.depth_mm.cols || r >= b.depth_mm.rows) return 0.0;
  return 0.001 * b.depth_mm.at<std::uint16_t>(r, c);
}

struct Row {
  const char* label;
  const char* group;
  const char* key;
  int decimals;
  double scale = 1.0;  // metres shown as millimetres
};

// One statistic of a run's section, "-" when the run has no such number (an older or partial section).
std::string cell(const nlohmann::json& section, const Row& row) {
  const auto g = section.find(row.group);
  if (g == section.end() || !g->is_object()) return "-";
  const auto v = g->find(row.key);
  if (v == g->end() || !v->is_number()) return "-";
  return fmt::format("{:.{}f}", row.scale * v->get<double>(), row.decimals);
}

constexpr Row kRows[] = {
    {"keypoints with depth, median share per frame", "depth_share", "median", 3},
    {"reprojection error after pose opt., median (px)", "reprojection_px", "median", 3},
    {"reprojection error after pose opt., p95 (px)", "reprojection_px", "p95", 3},
    {"depth residual after pose opt., median (mm)", "depth_residual_m", "median", 2, 1000.0},
    {"depth residual after pose opt., p95 (mm)", "depth_residual_m", "p95", 2, 1000.0},
    {"depth residual / z^2, median (mm/m^2)", "depth_residual_over_z2", "median", 2, 1000.0},
    {"depth residual / z^2, p95 (mm/m^2)", "depth_residual_over_z2", "p95", 2, 1000.0},
    {"track length, median (keyframes per point)", "track_length", "median", 1},
    {"track length, p90", "track_length", "p90", 1},
    {"track length, mean", "track_length", "mean", 2},
    {"keyframe depth disagreement, median (abs dz / z)", "depth_consistency", "median", 4},
    {"keyframe depth disagreement, p90 (abs dz / z)", "depth_consistency", "p90", 4},
    {"inlier observations", "reprojection_px", "observations", 0},
    {"map points", "track_length", "points", 0},
    {"distant keyframes' depth disagreement, mean of pair medians", "long_range_consistency", "mean", 4},
    {"... the same at the ground truth's poses", "long_range_consistency_groundtruth", "mean", 4},
    {"keyframe pairs compared", "depth_consistency", "pairs", 0},
    {"distant keyframe pairs compared", "long_range_consistency", "pairs", 0},
};

}  // namespace

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const double rank = std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size()));
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(std::max(rank, 1.0)) - 1);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

// Nearest pixels, never averaged: an average across a depth edge would invent a surface between the two.
KeyframeDepth keep_keyframe_depth(double timestamp, bool new_segment, const cv::Mat& depth_m) {
  return {timestamp, new_segment, slam::depth_mm_every(depth_m, KeyframeDepth::kDepthStep)};
}

std::vector<double> depth_disagreement(const KeyframeDepth& a, const Eigen::Isometry3d& T_wa, const KeyframeDepth& b,
                                       const Eigen::Isometry3d& T_wb, const PinholeCamera& cam) {
  std::vector<double> out;
  if (a.depth_mm.empty() || b.depth_mm.empty()) return out;
  const Eigen::Isometry3d T_ba = T_wb.inverse() * T_wa;
  constexpr int every = kSampleStep / KeyframeDepth::kDepthStep;
  for (int r = 0; r < a.depth_mm.rows; r += every) {
    for (int c = 0; c < a.depth_mm.cols; c += every) {
      const double za = 0.001 * a.depth_mm.at<std::uint16_t>(r, c);
      if (za <= 0) continue;
      const double u = c * KeyframeDepth::kDepthStep, v = r * KeyframeDepth::kDepthStep;
      const Eigen::Vector3d p_b = T_ba * cam.unproject(u, v, za);
      if (p_b.z() <= 0) continue;
      const Eigen::Vector2d uv = cam.project(p_b);
      if (!cam.in_image(uv.x(), uv.y())) continue;
      const double zb = kept_depth_at(b, uv.x(), uv.y());
      if (zb > 0) out.push_back(std::abs(p_b.z() - zb) / zb);
    }
  }
  return out;
}

DepthConsistency depth_consistency(const std::vector<KeyframeDepth>& keyframes, const Trajectory& final_poses,
                                   const PinholeCamera& cam) {
  std::map<double, Eigen::Isometry3d> pose_at;
  for (const StampedPose& p : final_poses) pose_at.emplace(p.timestamp, p.T_wc);
  DepthConsistency dc;
  for (std::size_t i = 1; i < keyframes.size(); ++i) {
    const KeyframeDepth &a = keyframes[i - 1], &b = keyframes[i];
    const auto pa = pose_at.find(a.timestamp), pb = pose_at.find(b.timestamp);
    if (b.new_segment || pa == pose_at.end() || pb == pose_at.end()) continue;
    const std::vector<double> d = depth_disagreement(a, pa->second, b, pb->second, cam);
    if (d.empty()) continue;
    dc.disagreement.insert(dc.disagreement.end(), d.begin(), d.end());
    ++dc.pairs;
  }
  return dc;
}

namespace {

// Samples of a that depth_disagreement() would try: those with depth.
std::size_t samples_with_depth(const KeyframeDepth& a) {
  constexpr int every = kSampleStep / KeyframeDepth::kDepthStep;
  std::size_t n = 0;
  for (int r = 0; r < a.depth_mm.rows; r += every)
    for (int c = 0; c < a.depth_mm.cols; c += every) n += a.depth_mm.at<std::uint16_t>(r, c) > 0;
  return n;
}

}  // namespace

LongRangeConsistency long_range_consistency(const std::vector<KeyframeDepth>& keyframes, const Trajectory& poses,
                                            const PinholeCamera& cam, const DistantPairs& rule) {
  std::map<double, Eigen::Isometry3d> pose_at;
  for (const StampedPose& p : poses) pose_at.emplace(p.timestamp, p.T_wc);
  std::vector<std::pair<std::size_t, std::size_t>> candidates;
  for (std::size_t i = 0; i < keyframes.size(); ++i)
    for (std::size_t j = i + 1; j < keyframes.size(); ++j) {
      const auto pa = pose_at.find(keyframes[i].timestamp), pb = pose_at.find(keyframes[j].timestamp);
      if (keyframes[j].timestamp - keyframes[i].timestamp < rule.min_gap_s || pa == pose_at.end() ||
          pb == pose_at.end() || !views_may_overlap(pa->second, pb->second, rule.max_angle_deg, rule.max_distance_m))
        continue;
      candidates.emplace_back(i, j);
    }
  LongRangeConsistency out;
  out.candidates = candidates.size();
  const std::size_t n = std::min(candidates.size(), rule.max_pairs);
  for (std::size_t k = 0; k < n; ++k) {
    const auto [i, j] = candidates[k * candidates.size() / n];
    const KeyframeDepth &a = keyframes[i], &b = keyframes[j];
    std::vector<double> d = depth_disagreement(a, pose_at.at(a.timestamp), b, pose_at.at(b.timestamp), cam);
    std::erase_if(d, [&](double x) { return x >= rule.same_surface; });
    const std::size_t with_depth = samples_with_depth(a);
    if (d.empty() || static_cast<double>(d.size()) < rule.min_overlap * static_cast<double>(with_depth)) continue;
    out.pair_median.push_back(percentile(std::move(d), 0.5));
  }
  return out;
}

nlohmann::json long_range_section(const LongRangeConsistency& c, const DistantPairs& rule) {
  return {{"mean", mean(c.pair_median)},
          {"median", percentile(c.pair_median, 0.5)},
          {"pairs", c.pair_median.size()},
          {"candidates", c.candidates},
          {"min_gap_s", rule.min_gap_s}};
}

std::vector<double> track_lengths(const slam::Map& map) {
  std::vector<double> n;
  for (const auto& mp : map.map_points())
    if (mp && !mp->is_bad()) n.push_back(mp->num_observations());
  return n;
}

nlohmann::json sensor_section(const SensorSamples& s) {
  const DepthConsistency& dc = s.consistency;
  const std::vector<double>&dz = s.depth_residual_m, &dz2 = s.depth_residual_over_z2;
  return {
      {"depth_share", {{"median", percentile(s.depth_share, 0.5)}, {"frames", s.depth_share.size()}}},
      {"reprojection_px",
       {{"median", percentile(s.reprojection_px, 0.5)},
        {"p95", percentile(s.reprojection_px, 0.95)},
        {"observations", s.reprojection_observations ? s.reprojection_observations : s.reprojection_px.size()},
        {"frames", s.residual_frames}}},
      {"depth_residual_m",
       {{"median", percentile(dz, 0.5)}, {"p95", percentile(dz, 0.95)}, {"observations", s.depth_observations ? s.depth_observations : dz.size()}}},
      {"depth_residual_over_z2", {{"median", percentile(dz2, 0.5)}, {"p95", percentile(dz2, 0.95)}}},
      {"track_length",
       {{"median", percentile(s.track_length, 0.5)},
        {"p90", percentile(s.track_length, 0.9)},
        {"mean", mean(s.track_length)},
        {"points", s.track_length.size()}}},
      {"depth_consistency",
       {{"median", percentile(dc.disagreement, 0.5)},
        {"p90", percentile(dc.disagreement, 0.9)},
        {"pixels", dc.disagreement.size()},
        {"pairs", dc.pairs},
        {"sample_step_px", kSampleStep}}},
      {"long_range_consistency", long_range_section(s.long_range)},
  };
}

nlohmann::json read_sensor_section(const fs::path& run_dir) {
  if (!fs::is_directory(run_dir)) throw InputError(run_dir.string() + ": no such run folder");
  const fs::path file = run_dir / "metrics.json";
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": missing (not a finished varslam run folder?)");
  nlohmann::json m;
  try {
    m = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file.string() + ": not valid JSON: " + e.what());
  }
  if (!m.is_object() || !m.contains("sensor") || !m["sensor"].is_object())
    throw InputError(file.string() + ": no \"sensor\" section (written by varslam runs since issue #33; run again)");
  return m["sensor"];
}

std::string sensor_table_markdown(const std::vector<std::string>& names, const std::vector<nlohmann::json>& sections) {
  std::string t = "| statistic |";
  std::string rule = "|---|";
  for (const std::string& n : names) {
    t += " " + n + " |";
    rule += "---:|";
  }
  t += "\n" + rule + "\n";
  for (const Row& row : kRows) {
    t += std::string("| ") + row.label + " |";
    for (const nlohmann::json& s : sections) t += " " + cell(s, row) + " |";
    t += "\n";
  }
  return t;
}

}  // namespace varslam::run
