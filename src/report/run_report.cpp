#include "report/run_report.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/error.hpp"
#include "eval/ate.hpp"
#include "eval/eval_report.hpp"
#include "io/atomic_file.hpp"
#include "io/trajectory_io.hpp"
#include "report/html.hpp"

namespace varslam::report {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The stages the runner times, in pipeline order, with the names people read.
const std::vector<std::pair<const char*, const char*>> kStages = {
    {"load", "load"},          {"extract", "extract"},
    {"filter", "filter"},      {"match", "match"},
    {"pose_optimization", "pose opt"}, {"tracking", "tracking"},
    {"keyframe_processing", "keyframe"}, {"local_ba", "local BA"}};

nlohmann::json read_json(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot open");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file.string() + ": not valid JSON: " + e.what());
  }
}

// A missing or unreadable optional trajectory shows as an empty plot, never as a failed report.
Trajectory read_optional_trajectory(const std::filesystem::path& file, std::string& problems) {
  if (!std::filesystem::exists(file)) return {};
  try {
    return read_tum_trajectory(file);
  } catch (const InputError& e) {
    problems += std::string(e.what()) + "\n";
    spdlog::warn("report: drawn without {}: {}", file.filename().string(), e.what());
    return {};
  }
}

// Ground truth restricted to the estimate's time span (plus a margin), so a short run on a long real recording
// is not drawn as a dot inside the whole recording.
Trajectory clip_to(const Trajectory& gt, const Trajectory& est) {
  if (est.empty()) return gt;
  const double lo = est.front().timestamp - 1.0, hi = est.back().timestamp + 1.0;
  Trajectory out;
  for (const auto& p : gt)
    if (p.timestamp >= lo && p.timestamp <= hi) out.push_back(p);
  return out;
}

std::string row(const std::string& name, const std::string& value) {
  return "<tr><th class=\"l\">" + html_escape(name) + "</th><td>" + html_escape(value) + "</td></tr>\n";
}

// Two plots side by side in a 1280 px wide window.
Plot sized(Plot plot) {
  const double scale = 600.0 / plot.options().width;
  plot.options().width = 600;
  plot.options().height = static_cast<int>(plot.options().height * scale);
  return plot;
}

std::string cm(double metres) { return std::isfinite(metres) ? format_number(100.0 * metres, 2) + " cm" : "n/a"; }

std::string key_numbers_table(const nlohmann::json& m) {
  std::string t = "<table id=\"key-numbers\">\n";
  auto integer = [&](const char* key) {
    const double v = json_number(m, {key});
    return std::isfinite(v) ? format_number(v, 0) : std::string("n/a");
  };
  t += row("frames", integer("frames"));
  t += row("tracked frames", integer("tracked_frames"));
  t += row("lost frames", integer("lost_frames"));
  t += row("map segments", integer("map_segments"));
  t += row("relocalizations", integer("relocalizations"));
  t += row("loops closed", m.contains("loops") && m["loops"].is_array() ? std::to_string(m["loops"].size()) : "n/a");
  t += row("keyframes", integer("keyframes"));
  t += row("map points", integer("map_points"));
  t += row("ATE RMSE", cm(json_number(m, {"ate", "rmse"})));
  t += row("ATE mean", cm(json_number(m, {"ate", "mean"})));
  t += row("ATE median", cm(json_number(m, {"ate", "median"})));
  t += row("ATE max", cm(json_number(m, {"ate", "max"})));
  t += row("ATE pairs", format_number(json_number(m, {"ate", "pairs"}), 0));
  t += row("correct rate", format_number(100.0 * json_number(m, {"ate", "correct_rate"}), 1) + " %");
  t += row("RPE translation (per s)", cm(json_number(m, {"rpe", "trans_rmse"})));
  t += row("RPE rotation (per s)", format_number(json_number(m, {"rpe", "rot_rmse_deg"}), 3) + " deg");
  t += row("frames per second", format_number(json_number(m, {"fps"}), 1));
  t += row("wall time", format_number(json_number(m, {"wall_seconds"}), 1) + " s");
  t += row("tracking median / p95", format_number(json_number(m, {"timings", "tracking", "median_ms"}), 1) + " / " +
                                        format_number(json_number(m, {"timings", "tracking", "p95_ms"}), 1) + " ms");
  if (m.contains("realtime")) {
    t += row("latency median / p95 (frame in to pose out)",
             format_number(json_number(m, {"realtime", "latency", "median_ms"}), 1) + " / " +
                 format_number(json_number(m, {"realtime", "latency", "p95_ms"}), 1) + " ms");
    t += row("frames late / dropped (a newer one had arrived)",
             format_number(json_number(m, {"realtime", "late_frames"}), 0) + " / " +
                 format_number(json_number(m, {"realtime", "dropped_frames"}), 0));
    t += row("mapping queue median / max", format_number(json_number(m, {"realtime", "mapping_queue", "median"}), 0) +
                                               " / " + format_number(json_number(m, {"realtime", "mapping_queue", "max"}), 0));
    t += row("Local BA skipped / cut short", format_number(json_number(m, {"realtime", "local_ba_skipped"}), 0) + " / " +
                                                 format_number(json_number(m, {"realtime", "local_ba_cut_short"}), 0) +
                                                 " of " + format_number(json_number(m, {"realtime", "keyframes_mapped"}), 0) +
                                                 " keyframes");
  }
  t += "</table>\n";
  return t;
}

std::string describe_run(const RunReportInputs& in) {
  const auto& m = in.metrics;
  auto str = [](const nlohmann::json& j, std::initializer_list<const char*> keys) -> std::string {
    const nlohmann::json* cur = &j;
    for (const char* k : keys) {
      if (!cur->is_object() || !cur->contains(k)) return "n/a";
      cur = &(*cur)[k];
    }
    return cur->is_string() ? cur->get<std::string>() : cur->dump();
  };
  std::string s = "<p>dataset <code>" + html_escape(str(m, {"dataset"})) + "</code>, mode " +
                  html_escape(str(m, {"mode"})) + ", kernels: tracking <b>" +
                  html_escape(str(m, {"kernels", "tracking"})) + "</b>, mapping <b>" +
                  html_escape(str(m, {"kernels", "mapping"})) + "</b>, detector <b>" +
                  html_escape(m.contains("semantic") ? str(m, {"semantic", "detector"}) : std::string("none")) +
                  "</b>";
  if (in.scenario.is_object()) s += ", scenario <b>" + html_escape(str(in.scenario, {"scenario"})) + "</b>";
  return s + "</p>\n";
}

}  // namespace

double json_number(const nlohmann::json& j, std::initializer_list<const char*> keys) {
  const nlohmann::json* cur = &j;
  for (const char* k : keys) {
    if (!cur->is_object()) return kNaN;
    const auto it = cur->find(k);
    if (it == cur->end()) return kNaN;
    cur = &*it;
  }
  return cur->is_number() ? cur->get<double>() : kNaN;
}

Plot alpha_per_keyframe_plot(const nlohmann::json& metrics, double t0) {
  Plot plot({"Adaptive kernel: alpha per keyframe (local BA)", "time [s]", "alpha", 800, 420, false, true});
  std::vector<double> t, a, fitted;
  bool capped = false;
  if (metrics.contains("local_ba") && metrics["local_ba"].is_array()) {
    for (const auto& ba : metrics["local_ba"]) {
      const double alpha = json_number(ba, {"final_alpha"});
      const double stamp = json_number(ba, {"timestamp"});
      if (std::isfinite(alpha) && std::isfinite(stamp)) {
        const double fit = json_number(ba, {"fitted_alpha"});
        t.push_back(stamp - t0);
        a.push_back(alpha);
        fitted.push_back(std::isfinite(fit) ? fit : alpha);
        capped |= fitted.back() != alpha;
      }
    }
  }
  if (!t.empty()) {
    // Reference: alpha = 2 is the Gaussian (L2) loss, the upper end of the fitted range.
    const double t_end = *std::max_element(t.begin(), t.end());
    plot.add_line("alpha = 2 (L2)", {0.0, t_end}, {2.0, 2.0}, "#bbbbbb");
    // With mapping.alpha_max below 2 the solver uses the capped value; the fit shows how the residuals changed.
    if (capped) plot.add_line("fitted alpha (before the cap)", t, fitted, "#e377c2");
    plot.add_line("final alpha", t, a, "#9467bd");
    plot.add_scatter("", std::move(t), std::move(a), "#9467bd");
  }
  return plot;
}

Plot stage_timing_plot(const nlohmann::json& metrics) {
  Plot plot({"Per-stage time per call", "", "milliseconds", 800, 420, false, true});
  std::vector<std::string> names;
  std::vector<double> median, p95;
  for (const auto& [key, name] : kStages) {
    const double med = json_number(metrics, {"timings", key, "median_ms"});
    if (!std::isfinite(med)) continue;
    names.emplace_back(name);
    median.push_back(med);
    const double p = json_number(metrics, {"timings", key, "p95_ms"});
    p95.push_back(std::isfinite(p) ? p : 0.0);
  }
  if (!names.empty()) {
    plot.add_category_bars("median", names, std::move(median), "#1f77b4");
    plot.add_category_bars("p95", names, std::move(p95), "#ff7f0e");
  }
  return plot;
}

RunReportInputs load_run_report_inputs(const std::filesystem::path& run_dir,
                                       const std::filesystem::path& sequence_dir) {
  RunReportInputs in;
  in.run_dir = run_dir;
  const auto metrics_file = run_dir / "metrics.json";
  if (!std::filesystem::exists(metrics_file))
    throw InputError(metrics_file.string() + ": not found (is " + run_dir.string() + " the --out of varslam run?)");
  in.metrics = read_json(metrics_file);
  in.title = std::filesystem::absolute(run_dir).lexically_normal().filename().string();
  if (in.title.empty()) in.title = std::filesystem::absolute(run_dir).lexically_normal().parent_path().filename().string();

  in.sequence_dir = sequence_dir;
  if (in.sequence_dir.empty() && in.metrics.contains("dataset") && in.metrics["dataset"].is_string())
    in.sequence_dir = in.metrics["dataset"].get<std::string>();

  std::string problems;
  in.estimate = read_optional_trajectory(run_dir / "CameraTrajectory.txt", problems);
  if (!in.sequence_dir.empty()) {
    in.groundtruth = read_optional_trajectory(in.sequence_dir / "groundtruth.txt", problems);
    in.preview_uri = image_data_uri(in.sequence_dir / "preview.png");
    if (std::filesystem::exists(in.sequence_dir / "scenario.json")) {
      try {
        in.scenario = read_json(in.sequence_dir / "scenario.json");
      } catch (const InputError&) {
        in.scenario = nullptr;  // decoration only
      }
    }
  }
  if (!problems.empty()) in.metrics["report_problems"] = problems;
  return in;
}

std::string render_run_report(const RunReportInputs& in) {
  std::ostringstream h;
  h << page_head("varslam run " + in.title);
  h << "<body>\n<h1>varslam run: " << html_escape(in.title) << "</h1>\n" << describe_run(in);
  h << "<h2>Key numbers</h2>\n" << key_numbers_table(in.metrics);

  h << "<h2>Trajectory and error</h2>\n<div class=\"plots\">\n";
  double t0 = in.estimate.empty() ? 0.0 : in.estimate.front().timestamp;
  bool have_ate = false;
  if (in.estimate.size() >= 2 && in.groundtruth.size() >= 2) {
    try {
      // Same evaluation as the runner (TUM evaluate_ate), so the plot matches the numbers above.
      const AteResult ate = evaluate_ate(in.groundtruth, in.estimate);
      const Trajectory gt_span = clip_to(in.groundtruth, in.estimate);
      h << "<figure id=\"plot-trajectory\">" << inline_svg(sized(trajectory_top_view_plot(gt_span, ate))) << "</figure>\n";
      h << "<figure id=\"plot-ate-error\">" << inline_svg(sized(ate_error_plot(ate))) << "</figure>\n";
      if (!ate.pairs.empty()) t0 = ate.pairs.front().gt_timestamp;
      have_ate = true;
    } catch (const InputError& e) {
      h << "<p class=\"note\">ATE not computed: " << html_escape(e.what()) << "</p>\n";
    }
  }
  if (!have_ate && (in.estimate.size() < 2 || in.groundtruth.size() < 2))
    h << "<p class=\"note\">No trajectory plot: " << (in.estimate.size() < 2 ? "the run has fewer than 2 poses" : "no ground truth")
      << ".</p>\n";
  h << "</div>\n";

  h << "<h2>Adaptive kernel and timing</h2>\n<div class=\"plots\">\n";
  const Plot alpha = alpha_per_keyframe_plot(in.metrics, t0);
  if (alpha.series().empty())
    h << "<p class=\"note\" id=\"no-alpha\">No alpha per keyframe: the mapping kernel of this run is not adaptive.</p>\n";
  else
    h << "<figure id=\"plot-alpha\">" << inline_svg(sized(alpha)) << "</figure>\n";
  const Plot timing = stage_timing_plot(in.metrics);
  if (!timing.series().empty()) h << "<figure id=\"plot-timing\">" << inline_svg(sized(timing)) << "</figure>\n";
  h << "</div>\n";

  if (in.preview_uri) {
    h << "<h2>Sequence preview</h2>\n<img class=\"preview\" id=\"preview\" alt=\"preview of the sequence\" src=\""
      << *in.preview_uri << "\">\n";
  }
  if (in.metrics.contains("report_problems") && in.metrics["report_problems"].is_string())
    h << "<p class=\"note\">" << html_escape(in.metrics["report_problems"].get<std::string>()) << "</p>\n";
  h << "<p class=\"note\">run folder <code>" << html_escape(in.run_dir.string()) << "</code>, sequence <code>"
    << html_escape(in.sequence_dir.string()) << "</code></p>\n</body>\n</html>\n";
  return h.str();
}

void write_run_report(const std::filesystem::path& run_dir, const std::filesystem::path& sequence_dir,
                      const std::filesystem::path& out_html) {
  write_file_atomically(out_html, render_run_report(load_run_report_inputs(run_dir, sequence_dir)), "report");
}

}  // namespace varslam::report
