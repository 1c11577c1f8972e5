#pragma once
// index.html of a benchmark: bar charts per scenario and configuration, the tables, and a link to every run's
// report.html. Self-contained (inline SVG) apart from those links.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/svg_plot.hpp"
#include "report/bench_results.hpp"

namespace varslam::report {

/// Grouped bars: one group per scenario (mean over paths and seeds), one bar per configuration (and the peer
/// where `with_peer`). `figure` picks the value: "ate_rmse_cm", "ate_max_cm", "correct_rate_pct", "fps".
Plot bench_bar_chart(const std::vector<RunRecord>& records, const TableOptions& options, const std::string& figure,
                     bool with_peer);

std::string render_bench_summary_html(const nlohmann::json& results, const std::vector<RunRecord>& records,
                                      const TableOptions& options, const std::filesystem::path& out_dir);

}  // namespace varslam::report
