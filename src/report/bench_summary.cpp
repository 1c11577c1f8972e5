#include "report/bench_summary.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "report/html.hpp"
#include "report/run_report.hpp"

namespace varslam::report {
namespace {

std::string scenario_label(const RunRecord& r) { return r.scenario == "real" ? r.path_name : r.scenario; }

double pick(const CellMean& m, const std::string& figure) {
  if (figure == "ate_rmse_cm") return m.n_ate ? 100.0 * m.ate_rmse_m : 0.0;
  if (figure == "ate_max_cm") return m.n_ate ? 100.0 * m.ate_max_m : 0.0;
  if (figure == "correct_rate_pct") return m.n_ate ? 100.0 * m.correct_rate : 0.0;
  if (figure == "fps") return m.n_speed ? m.fps : 0.0;
  throw InputError("bench_bar_chart: unknown figure '" + figure + "'");
}

std::string link(const std::filesystem::path& target, const std::filesystem::path& base, const std::string& text) {
  const std::string rel = target.lexically_relative(base).string();
  return "<a href=\"" + html_escape(rel.empty() ? target.string() : rel) + "\">" + html_escape(text) + "</a>";
}

}  // namespace

Plot bench_bar_chart(const std::vector<RunRecord>& records, const TableOptions& o, const std::string& figure,
                     bool with_peer) {
  static const std::map<std::string, std::string> titles = {{"ate_rmse_cm", "ATE RMSE [cm]"},
                                                            {"ate_max_cm", "ATE max [cm]"},
                                                            {"correct_rate_pct", "correct rate [%]"},
                                                            {"fps", "frames per second"}};
  const auto t = titles.find(figure);
  Plot plot({t == titles.end() ? figure : t->second + " per scenario (mean over paths and seeds)", "",
             t == titles.end() ? figure : t->second, 620, 360, false, true});
  std::vector<std::string> scenarios;
  for (const auto& r : records)
    if (std::find(scenarios.begin(), scenarios.end(), scenario_label(r)) == scenarios.end())
      scenarios.push_back(scenario_label(r));
  std::vector<std::string> columns = o.configs;
  if (with_peer && o.peer) columns.push_back("peer");
  for (std::size_t c = 0; c < columns.size(); ++c) {
    std::vector<double> heights;
    for (const auto& s : scenarios) {
      std::vector<const RunRecord*> cell;
      for (const auto& r : records)
        if (r.config == columns[c] && scenario_label(r) == s) cell.push_back(&r);
      heights.push_back(pick(mean_of(cell), figure));
    }
    plot.add_category_bars(columns[c] == "peer" ? o.peer_name : columns[c], scenarios, std::move(heights),
                           palette_color(c));
  }
  return plot;
}

std::string render_bench_summary_html(const nlohmann::json& results, const std::vector<RunRecord>& records,
                                      const TableOptions& o, const std::filesystem::path& out_dir) {
  std::ostringstream h;
  h << page_head("varslam benchmark") << "<body>\n<h1>varslam benchmark</h1>\n";
  const auto str = [&](const char* a, const char* b = nullptr) -> std::string {
    const nlohmann::json* j = results.contains(a) ? &results[a] : nullptr;
    if (j && b) j = j->contains(b) ? &(*j)[b] : nullptr;
    if (!j) return "n/a";
    return j->is_string() ? j->get<std::string>() : j->dump();
  };
  h << "<p>version <code>" << html_escape(str("version", "git_describe")) << "</code>, started "
    << html_escape(str("started_utc")) << ", " << html_escape(format_number(json_number(results, {"wall_seconds"}), 0))
    << " s wall; machine: " << html_escape(str("machine", "nproc")) << " cores, "
    << html_escape(str("machine", "cpu_model")) << ", load average "
    << html_escape(format_number(json_number(results, {"machine", "load_average_1min"}), 1)) << " at the start</p>\n";
  h << "<p>command: <code>" << html_escape(str("command_line")) << "</code></p>\n";

  h << "<h2>Summary</h2>\n<div class=\"plots\">\n";
  for (const char* figure : {"ate_rmse_cm", "ate_max_cm", "correct_rate_pct", "fps"}) {
    h << "<figure id=\"chart-" << figure << "\">"
      << inline_svg(bench_bar_chart(records, o, figure, std::string(figure).rfind("ate", 0) == 0)) << "</figure>\n";
  }
  h << "</div>\n";

  h << "<h2>Tables</h2>\n<pre id=\"table-md\">" << html_escape(render_markdown_tables(records, o)) << "</pre>\n";

  h << "<h2>Runs</h2>\n<table id=\"runs\">\n<tr><th class=\"l\">sequence</th><th class=\"l\">config</th>"
       "<th>ATE RMSE [cm]</th><th>ATE max [cm]</th><th>correct rate [%]</th><th>fps</th><th>wall [s]</th>"
       "<th class=\"l\">report</th></tr>\n";
  for (const auto& r : records) {
    const RunFigures& f = r.figures;
    h << "<tr><td class=\"l\">" << html_escape(r.sequence_id) << "</td><td class=\"l\">" << html_escape(r.config)
      << "</td><td>" << format_number(100.0 * f.ate_rmse_m, 2) << "</td><td>" << format_number(100.0 * f.ate_max_m, 2)
      << "</td><td>" << format_number(100.0 * f.correct_rate, 1) << "</td><td>" << format_number(f.fps, 1)
      << "</td><td>" << format_number(f.wall_seconds, 1) << "</td><td class=\"l\">";
    if (!r.ok) h << "<b>failed</b>: " << html_escape(r.error) << ' ';
    if (!r.report_html.empty()) h << link(r.report_html, out_dir, "report");
    else h << link(r.run_dir, out_dir, "folder");
    h << "</td></tr>\n";
  }
  h << "</table>\n</body>\n</html>\n";
  return h.str();
}

}  // namespace varslam::report
