#include "report/bench_results.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "report/html.hpp"
#include "report/run_report.hpp"

namespace varslam::report {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A cell value; a trailing '*' flags a mean over fewer runs than the cell has (some failed or had no ATE).
std::string cell(double v, double scale, int decimals, std::size_t n, std::size_t total) {
  if (n == 0) return total == 0 ? "" : "fail";
  std::string s = format_number(v * scale, decimals);
  if (n < total) s += "*";
  return s;
}

struct Group {
  std::string scenario, path;  // path empty = whole scenario
  std::map<std::string, std::vector<const RunRecord*>> by_config;
};

std::string render_table(const std::vector<Group>& groups, const TableOptions& o, bool with_path) {
  std::ostringstream t;
  t << "| scenario |" << (with_path ? " path |" : "");
  for (const auto& c : o.configs)
    t << ' ' << c << " RMSE | " << c << " max | " << c << " CR % | " << c << " fps | " << c << " trk ms |";
  if (o.peer) t << ' ' << o.peer_name << " RMSE | " << o.peer_name << " max | " << o.peer_name << " s |";
  t << "\n|---|" << (with_path ? "---|" : "");
  for (std::size_t i = 0; i < o.configs.size(); ++i) t << "--:|--:|--:|--:|--:|";
  if (o.peer) t << "--:|--:|--:|";
  t << '\n';
  for (const auto& g : groups) {
    t << "| " << g.scenario << " |" << (with_path ? " " + g.path + " |" : "");
    for (const auto& c : o.configs) {
      const auto it = g.by_config.find(c);
      const CellMean m = it == g.by_config.end() ? CellMean{} : mean_of(it->second);
      t << ' ' << cell(m.ate_rmse_m, 100, 2, m.n_ate, m.n_runs) << " | " << cell(m.ate_max_m, 100, 2, m.n_ate, m.n_runs)
        << " | " << cell(m.correct_rate, 100, 1, m.n_ate, m.n_runs) << " | " << cell(m.fps, 1, 1, m.n_speed, m.n_runs)
        << " | " << cell(m.tracking_median_ms, 1, 1, m.n_speed, m.n_runs) << " |";
    }
    if (o.peer) {
      const auto it = g.by_config.find("peer");
      const CellMean m = it == g.by_config.end() ? CellMean{} : mean_of(it->second);
      t << ' ' << cell(m.ate_rmse_m, 100, 2, m.n_ate, m.n_runs) << " | " << cell(m.ate_max_m, 100, 2, m.n_ate, m.n_runs)
        << " | " << cell(m.wall_seconds, 1, 1, m.n_wall, m.n_runs) << " |";
    }
    t << '\n';
  }
  return t.str();
}

}  // namespace

RunFigures figures_from_metrics(const nlohmann::json& m) {
  RunFigures f{kNaN, kNaN, kNaN, kNaN, kNaN, kNaN};
  if (!m.is_object()) return f;
  f.ate_rmse_m = json_number(m, {"ate", "rmse"});
  f.ate_max_m = json_number(m, {"ate", "max"});
  f.correct_rate = json_number(m, {"ate", "correct_rate"});
  f.fps = json_number(m, {"fps"});
  f.tracking_median_ms = json_number(m, {"timings", "tracking", "median_ms"});
  f.wall_seconds = json_number(m, {"wall_seconds"});
  f.ate_live_rmse_m = json_number(m, {"ate_live", "rmse"});
  f.ate_live_max_m = json_number(m, {"ate_live", "max"});
  f.dragged_events = json_number(m, {"ate_live", "dragged_events"});
  f.local_ba_median_ms = json_number(m, {"timings", "local_ba", "median_ms"});
  return f;
}

CellMean mean_of(const std::vector<const RunRecord*>& records) {
  CellMean m;
  m.n_runs = records.size();
  for (const RunRecord* r : records) {
    if (!r->ok) continue;
    ++m.n_ok;
    const RunFigures& f = r->figures;
    if (std::isfinite(f.ate_rmse_m) && std::isfinite(f.ate_max_m)) {
      ++m.n_ate;
      m.ate_rmse_m += f.ate_rmse_m;
      m.ate_max_m += f.ate_max_m;
      m.correct_rate += std::isfinite(f.correct_rate) ? f.correct_rate : 0.0;
    }
    if (std::isfinite(f.fps) && std::isfinite(f.tracking_median_ms)) {
      ++m.n_speed;
      m.fps += f.fps;
      m.tracking_median_ms += f.tracking_median_ms;
    }
    if (std::isfinite(f.wall_seconds)) {
      ++m.n_wall;
      m.wall_seconds += f.wall_seconds;
    }
  }
  const auto div = [](double& v, std::size_t n) { v = n ? v / static_cast<double>(n) : kNaN; };
  div(m.ate_rmse_m, m.n_ate);
  div(m.ate_max_m, m.n_ate);
  div(m.correct_rate, m.n_ate);
  div(m.fps, m.n_speed);
  div(m.tracking_median_ms, m.n_speed);
  div(m.wall_seconds, m.n_wall);
  return m;
}

namespace {

// Mean ATE RMSE of a scenario over the (path, seed) pairs that also have a static run with an ATE, and the
// static mean over the same pairs: a ratio of two means over different seeds would compare different scenes.
struct PairedMeans {
  double dynamic_m = 0, static_m = 0;
  std::size_t pairs = 0, runs = 0;
};

std::string ratio_cell(const PairedMeans& p) {
  if (p.pairs == 0 || p.static_m <= 0) return p.runs == 0 ? "" : "fail";
  std::string s = format_number(p.dynamic_m / p.static_m, 2);
  if (p.pairs < p.runs) s += "*";
  return s;
}

}  // namespace

std::string render_static_ratio_table(const std::vector<RunRecord>& records, const std::vector<std::string>& configs) {
  // static ATE per (path, config, seed)
  std::map<std::tuple<std::string, std::string, std::uint64_t>, double> stat;
  std::vector<std::string> scenarios, paths;
  auto note = [](std::vector<std::string>& v, const std::string& x) {
    if (std::find(v.begin(), v.end(), x) == v.end()) v.push_back(x);
  };
  for (const auto& r : records) {
    if (r.scenario == "static" && r.ok && std::isfinite(r.figures.ate_rmse_m))
      stat[{r.path_name, r.config, r.seed}] = r.figures.ate_rmse_m;
    if (r.scenario != "static" && r.scenario != "real") note(scenarios, r.scenario);
    if (r.scenario != "real") note(paths, r.path_name);
  }
  if (stat.empty() || scenarios.empty()) return {};
  auto paired = [&](const std::string& scenario, const std::string& path, const std::string& config) {
    PairedMeans p;
    for (const auto& r : records) {
      if (r.scenario != scenario || r.config != config || (!path.empty() && r.path_name != path)) continue;
      ++p.runs;
      const auto s = stat.find({r.path_name, r.config, r.seed});
      if (!r.ok || !std::isfinite(r.figures.ate_rmse_m) || s == stat.end()) continue;
      p.dynamic_m += r.figures.ate_rmse_m;
      p.static_m += s->second;
      ++p.pairs;
    }
    return p;
  };
  std::ostringstream t;
  t << "| scenario | path |";
  for (const auto& c : configs) t << ' ' << c << " |";
  t << "\n|---|---|";
  for (std::size_t i = 0; i < configs.size(); ++i) t << "--:|";
  t << '\n';
  for (const auto& sc : scenarios) {
    std::vector<std::string> rows = paths;
    rows.push_back("");  // all paths
    for (const auto& path : rows) {
      std::vector<PairedMeans> cells;
      for (const auto& c : configs) cells.push_back(paired(sc, path, c));
      if (std::none_of(cells.begin(), cells.end(), [](const PairedMeans& p) { return p.runs > 0; })) continue;
      t << "| " << sc << " | " << (path.empty() ? "all" : path) << " |";
      for (const auto& cell : cells) t << ' ' << ratio_cell(cell) << " |";
      t << '\n';
    }
  }
  return t.str();
}

namespace {

// One configuration's runs of one table row, for the live table.
struct LiveCell {
  std::size_t runs = 0, final_n = 0, live_n = 0, drag_n = 0;
  double final_sum = 0, final_worst = 0, live_sum = 0, live_worst = 0, drags = 0;
  std::vector<double> tracking_ms, local_ba_ms;

  void add(const RunRecord& r) {
    ++runs;
    if (!r.ok) return;
    const RunFigures& f = r.figures;
    if (std::isfinite(f.ate_rmse_m)) {
      ++final_n;
      final_sum += f.ate_rmse_m;
      final_worst = std::max(final_worst, f.ate_rmse_m);
    }
    if (std::isfinite(f.ate_live_rmse_m)) {
      ++live_n;
      live_sum += f.ate_live_rmse_m;
      live_worst = std::max(live_worst, f.ate_live_rmse_m);
    }
    if (std::isfinite(f.dragged_events)) {
      ++drag_n;
      drags += f.dragged_events;
    }
    if (std::isfinite(f.tracking_median_ms)) tracking_ms.push_back(f.tracking_median_ms);
    if (std::isfinite(f.local_ba_median_ms)) local_ba_ms.push_back(f.local_ba_median_ms);
  }
};

double median_of(std::vector<double> v) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string live_row(const LiveCell& c) {
  auto mean = [](double sum, std::size_t n) { return n ? sum / static_cast<double>(n) : kNaN; };
  // A peer writes no live trajectory and no timings: "-", not "fail".
  const bool no_live = c.live_n == 0 && c.final_n > 0;
  auto median_cell = [&](const std::vector<double>& v, int decimals) {
    return v.empty() && c.final_n > 0 ? std::string("-") : cell(median_of(v), 1, decimals, v.size(), c.runs);
  };
  return cell(mean(c.final_sum, c.final_n), 100, 2, c.final_n, c.runs) + " | " +
         cell(c.final_worst, 100, 2, c.final_n, c.runs) + " | " +
         (no_live ? "-" : cell(mean(c.live_sum, c.live_n), 100, 2, c.live_n, c.runs)) + " | " +
         (no_live ? "-" : cell(c.live_worst, 100, 2, c.live_n, c.runs)) + " | " + cell(c.drags, 1, 0, c.drag_n, c.runs) + " | " +
         median_cell(c.tracking_ms, 1) + " | " + median_cell(c.local_ba_ms, 0);
}

}  // namespace

std::string render_live_table(const std::vector<RunRecord>& records, const std::vector<std::string>& configs) {
  if (std::none_of(records.begin(), records.end(),
                   [](const RunRecord& r) { return std::isfinite(r.figures.ate_live_rmse_m); }))
    return "";
  // Rows: each scenario's paths in order of appearance, then the scenario over all paths.
  std::vector<std::string> scenarios, paths;
  for (const auto& r : records) {
    if (r.scenario == "real") continue;
    if (std::find(scenarios.begin(), scenarios.end(), r.scenario) == scenarios.end()) scenarios.push_back(r.scenario);
    if (std::find(paths.begin(), paths.end(), r.path_name) == paths.end()) paths.push_back(r.path_name);
  }
  paths.push_back("all");
  std::ostringstream t;
  t << "| scenario | path |";
  for (const auto& c : configs)
    t << ' ' << c << " final mean | " << c << " final worst | " << c << " live mean | " << c << " live worst | " << c
      << " dragged | " << c << " trk ms | " << c << " LBA ms |";
  t << "\n|---|---|";
  for (std::size_t i = 0; i < configs.size(); ++i) t << "--:|--:|--:|--:|--:|--:|--:|";
  t << '\n';
  for (const auto& sc : scenarios)
    for (const auto& path : paths) {
      const bool all = path == "all";
      std::vector<LiveCell> cells(configs.size());
      std::size_t n = 0;
      for (const auto& r : records) {
        if (r.scenario != sc || (!all && r.path_name != path)) continue;
        const auto c = std::find(configs.begin(), configs.end(), r.config);
        if (c == configs.end()) continue;
        cells[static_cast<std::size_t>(c - configs.begin())].add(r);
        ++n;
      }
      if (n == 0) continue;
      t << "| " << sc << " | " << path << " |";
      for (const auto& lc : cells) t << ' ' << live_row(lc) << " |";
      t << '\n';
    }
  return t.str();
}

std::string render_markdown_tables(const std::vector<RunRecord>& records, const TableOptions& o) {
  std::vector<Group> per_scenario, per_path;
  auto find_or_add = [](std::vector<Group>& groups, const std::string& scenario, const std::string& path) -> Group& {
    for (auto& g : groups)
      if (g.scenario == scenario && g.path == path) return g;
    groups.push_back({scenario, path, {}});
    return groups.back();
  };
  for (const auto& r : records) {
    // Real folders are each their own row in both tables: averaging different recordings means nothing.
    const std::string scenario = r.scenario == "real" ? "real: " + r.path_name : r.scenario;
    find_or_add(per_scenario, scenario, "").by_config[r.config].push_back(&r);
    find_or_add(per_path, scenario, r.scenario == "real" ? std::string("-") : r.path_name).by_config[r.config].push_back(&r);
  }
  std::ostringstream md;
  md << "Per scenario (mean over camera paths and seeds). RMSE / max: ATE in cm; CR: correct rate (share of "
        "frames with an associated pose); fps: frames per second of the whole run; trk ms: median tracking time "
        "per frame. `*`: mean over fewer runs than planned (some failed or had no ATE); `fail`: no run gave a "
        "figure.\n\n";
  md << render_table(per_scenario, o, false);
  md << "\nPer scenario and camera path (mean over seeds):\n\n";
  md << render_table(per_path, o, true);
  const std::string ratios = render_static_ratio_table(records, o.configs);
  if (!ratios.empty()) {
    md << "\nATE RMSE against the static scene along the same path (mean over the seeds both have; 1 = the movers "
          "cost nothing; `*`: some runs had no static partner or failed):\n\n";
    md << ratios;
  }
  std::vector<std::string> live_configs = o.configs;
  if (o.peer) live_configs.push_back("peer");
  const std::string live = render_live_table(records, live_configs);
  if (!live.empty()) {
    md << "\nFinal and live ATE (the pose tracking gave each frame, as a robot uses it), in cm: mean and worst run's "
          "RMSE; dragged: times the live pose moved more than 10 cm against ground truth within one second, summed "
          "over the runs (a peer's on its final trajectory); trk / LBA ms: median over runs of each run's tracking "
          "and Local BA median:\n\n";
    md << live;
  }
  return md.str();
}

std::string replace_between_markers(const std::string& document, const std::string& generated,
                                    const std::string& document_name) {
  const auto begin = document.find(kTableBeginMarker);
  const auto end = document.find(kTableEndMarker);
  if (begin == std::string::npos || end == std::string::npos || end < begin)
    throw InputError(fmt::format("{}: needs the marker lines {} and {} (in that order) around the generated table",
                                 document_name, kTableBeginMarker, kTableEndMarker));
  const auto after_begin = begin + std::string(kTableBeginMarker).size();
  std::string body = generated;
  if (body.empty() || body.back() != '\n') body += '\n';
  return document.substr(0, after_begin) + "\n" + body + document.substr(end);
}

void update_benchmarks_md(const std::filesystem::path& file, const std::string& generated) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot read (create it with the two marker lines first)");
  std::stringstream buf;
  buf << in.rdbuf();
  const std::string updated = replace_between_markers(buf.str(), generated, file.string());
  write_file_atomically(file, updated, "Markdown file");
}

nlohmann::json to_json(const RunRecord& r) {
  auto num = [](double v) -> nlohmann::json { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  return {{"sequence", r.sequence_id},
          {"scenario", r.scenario},
          {"path", r.path_name},
          {"seed", r.seed},
          {"config", r.config},
          {"ok", r.ok},
          {"error", r.error},
          {"ate_rmse_m", num(r.figures.ate_rmse_m)},
          {"ate_max_m", num(r.figures.ate_max_m)},
          {"correct_rate", num(r.figures.correct_rate)},
          {"fps", num(r.figures.fps)},
          {"tracking_median_ms", num(r.figures.tracking_median_ms)},
          {"wall_seconds", num(r.figures.wall_seconds)},
          {"ate_live_rmse_m", num(r.figures.ate_live_rmse_m)},
          {"ate_live_max_m", num(r.figures.ate_live_max_m)},
          {"dragged_events", num(r.figures.dragged_events)},
          {"local_ba_median_ms", num(r.figures.local_ba_median_ms)},
          {"run_dir", r.run_dir.string()},
          {"report", r.report_html.string()}};
}

}  // namespace varslam::report
