#include "eval/eval_report.hpp"

#include <fmt/format.h>

#include <array>
#include <cstdio>

#include "core/error.hpp"

namespace varslam {
namespace {

nlohmann::json stats_json(const ErrorStatistics& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std},
          {"min", s.min},   {"max", s.max},   {"count", s.count}};
}

std::string row(const char* name, const ErrorStatistics& s, const char* unit) {
  return fmt::format("  {:<18} {:10.6f} {:10.6f} {:10.6f} {:10.6f} {:10.6f} {:10.6f}  {}\n", name, s.rmse, s.mean,
                     s.median, s.std, s.min, s.max, unit);
}

const std::array<const char*, 3> kAxisNames{"x", "y", "z"};

}  // namespace

EvalSummary evaluate_trajectory(const Trajectory& gt, const Trajectory& est, const EvalOptions& options) {
  EvalSummary s;
  s.options = options;
  s.gt_poses = gt.size();
  s.est_poses = est.size();
  s.ate = evaluate_ate(gt, est, options.ate);
  try {
    s.rpe = evaluate_rpe(gt, est, {options.rpe_delta_seconds, options.ate.offset, 1.0});
  } catch (const InputError& e) {
    s.rpe_unavailable = e.what();
  }
  s.frame_count_given = options.frame_count.has_value();
  s.frame_count = options.frame_count.value_or(est.size());
  s.correct_rate = correct_rate(s.ate.stats.count, s.frame_count);
  return s;
}

std::string format_eval_table(const EvalSummary& s) {
  std::string out;
  char buf[256];
  std::snprintf(buf, sizeof buf, "poses: ground truth %zu, estimate %zu; associated pairs %zu (max difference %.3f s)\n",
                s.gt_poses, s.est_poses, s.ate.stats.count, s.options.ate.max_difference);
  out += buf;
  out += "                           rmse       mean     median        std        min        max\n";
  out += row(s.options.ate.with_scale ? "ATE (Sim3 aligned)" : "ATE", s.ate.stats, "m");
  if (s.rpe) {
    std::snprintf(buf, sizeof buf, "RPE trans / %gs", s.options.rpe_delta_seconds);
    out += row(buf, s.rpe->translation, "m");
    std::snprintf(buf, sizeof buf, "RPE rot / %gs", s.options.rpe_delta_seconds);
    out += row(buf, s.rpe->rotation_deg, "deg");
    std::snprintf(buf, sizeof buf, "RPE pairs: %zu\n", s.rpe->pairs.size());
    out += buf;
  } else {
    out += "RPE: not available (" + s.rpe_unavailable + ")\n";
  }
  if (s.options.ate.with_scale) {
    std::snprintf(buf, sizeof buf, "alignment scale: %.6f\n", s.ate.alignment.scale);
    out += buf;
  }
  std::snprintf(buf, sizeof buf, "correct rate: %.2f %% (%zu pairs / %zu %s)\n", 100.0 * s.correct_rate,
                s.ate.stats.count, s.frame_count, s.frame_count_given ? "frames" : "estimate poses");
  out += buf;
  return out;
}

nlohmann::json eval_to_json(const EvalSummary& s, bool per_pair) {
  nlohmann::json j;
  const auto& a = s.ate.alignment;
  nlohmann::json rotation = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rotation.push_back({a.R(r, 0), a.R(r, 1), a.R(r, 2)});
  j["ate"] = stats_json(s.ate.stats);
  j["ate"]["pairs"] = s.ate.stats.count;
  j["ate"]["unit"] = "m";
  j["ate"]["max_difference_s"] = s.options.ate.max_difference;
  j["ate"]["offset_s"] = s.options.ate.offset;
  j["ate"]["with_scale"] = s.options.ate.with_scale;
  j["ate"]["alignment"] = {{"rotation", rotation}, {"translation", {a.t.x(), a.t.y(), a.t.z()}}, {"scale", a.scale}};
  if (s.rpe) {
    j["rpe"] = {{"delta_s", s.options.rpe_delta_seconds},
                {"pairs", s.rpe->pairs.size()},
                {"translation_m", stats_json(s.rpe->translation)},
                {"rotation_deg", stats_json(s.rpe->rotation_deg)}};
  } else {
    j["rpe"] = nullptr;
    j["rpe_unavailable"] = s.rpe_unavailable;
  }
  j["correct_rate"] = s.correct_rate;
  j["frame_count"] = s.frame_count;
  j["frame_count_source"] = s.frame_count_given ? "given" : "estimate poses";
  j["gt_poses"] = s.gt_poses;
  j["est_poses"] = s.est_poses;
  if (per_pair) {
    nlohmann::json gt_t = nlohmann::json::array();
    nlohmann::json est_t = nlohmann::json::array();
    nlohmann::json err = nlohmann::json::array();
    for (const auto& p : s.ate.pairs) {
      gt_t.push_back(p.gt_timestamp);
      est_t.push_back(p.est_timestamp);
      err.push_back(p.error);
    }
    j["ate_per_pair"] = {{"gt_timestamp", gt_t}, {"est_timestamp", est_t}, {"error_m", err}};
  }
  return j;
}

std::pair<int, int> top_view_axes(const Trajectory& gt) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : gt) mean += p.T_wc.translation();
  if (!gt.empty()) mean /= static_cast<double>(gt.size());
  Eigen::Vector3d var = Eigen::Vector3d::Zero();
  for (const auto& p : gt) var += (p.T_wc.translation() - mean).cwiseAbs2();
  int least = 0;
  var.minCoeff(&least);
  // Ties (e.g. no data) resolve to x-y, the usual top view for TUM ground truth.
  if (var.isApprox(Eigen::Vector3d::Constant(var.x())) || var.isZero()) least = 2;
  const int a = least == 0 ? 1 : 0;
  const int b = least == 2 ? 1 : 2;
  return {a, b};
}

Plot trajectory_top_view_plot(const Trajectory& gt, const AteResult& ate) {
  const auto [ia, ib] = top_view_axes(gt);
  Plot plot({"Trajectory (estimate aligned to ground truth)", std::string(kAxisNames[ia]) + " [m]",
             std::string(kAxisNames[ib]) + " [m]", 800, 640, true, true});
  std::vector<double> gx, gy, ex, ey;
  for (const auto& p : gt) {
    gx.push_back(p.T_wc.translation()[ia]);
    gy.push_back(p.T_wc.translation()[ib]);
  }
  for (const auto& p : ate.aligned_estimate) {
    ex.push_back(p.T_wc.translation()[ia]);
    ey.push_back(p.T_wc.translation()[ib]);
  }
  plot.add_line("ground truth", std::move(gx), std::move(gy), "#444444");
  plot.add_line("estimate (aligned)", std::move(ex), std::move(ey), "#1f77b4");
  if (!gt.empty()) {
    plot.add_scatter("start", {gt.front().T_wc.translation()[ia]}, {gt.front().T_wc.translation()[ib]}, "#2ca02c");
  }
  return plot;
}

Plot ate_error_plot(const AteResult& ate) {
  Plot plot({"ATE error over time", "time [s]", "translational error [m]", 800, 420, false, true});
  std::vector<double> t, e;
  const double t0 = ate.pairs.empty() ? 0.0 : ate.pairs.front().gt_timestamp;
  for (const auto& p : ate.pairs) {
    t.push_back(p.gt_timestamp - t0);
    e.push_back(p.error);
  }
  const double t_end = t.empty() ? 0.0 : t.back();
  plot.add_line("error", std::move(t), std::move(e), "#d62728");
  char label[64];
  std::snprintf(label, sizeof label, "RMSE %.4f m", ate.stats.rmse);
  plot.add_line(label, {0.0, t_end}, {ate.stats.rmse, ate.stats.rmse}, "#7f7f7f");
  return plot;
}

std::vector<std::filesystem::path> write_eval_plots(const Trajectory& gt, const EvalSummary& summary,
                                                    const std::filesystem::path& file) {
  const auto error_file =
      file.parent_path() / (file.stem().string() + "_ate_error" + file.extension().string());
  write_plot(trajectory_top_view_plot(gt, summary.ate), file);
  write_plot(ate_error_plot(summary.ate), error_file);
  return {file, error_file};
}

}  // namespace varslam
