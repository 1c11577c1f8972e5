#pragma once
// Benchmark results: one record per run, the paper-style Markdown tables (mean over seeds), and the
// generated-table block of BENCHMARKS.md.
#include <cstdint>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace varslam::report {

/// The figures a table shows for one run (NaN = not available, e.g. the run failed or had no ATE).
struct RunFigures {
  double ate_rmse_m;
  double ate_max_m;
  double correct_rate;  // 0..1
  double fps;
  double tracking_median_ms;
  double wall_seconds;
  // The live trajectory (each pose when tracking gave it) and its dragged events (eval/drag_events.hpp); for a
  // peer, which writes only its final trajectory, the events are counted on that.
  double ate_live_rmse_m = std::numeric_limits<double>::quiet_NaN();
  double ate_live_max_m = std::numeric_limits<double>::quiet_NaN();
  double dragged_events = std::numeric_limits<double>::quiet_NaN();
  double local_ba_median_ms = std::numeric_limits<double>::quiet_NaN();
};
RunFigures figures_from_metrics(const nlohmann::json& metrics);

/// One executed run (ours or the peer's) of one sequence.
struct RunRecord {
  std::string sequence_id;
  std::string scenario;   // synthetic scenario or "real"
  std::string path_name;  // camera path short name or real folder name
  std::uint64_t seed = 0;
  std::string config;     // configuration name, or "peer"
  bool ok = false;
  std::string error;      // why not ok
  RunFigures figures{};
  std::filesystem::path run_dir;
  std::filesystem::path report_html;  // empty when no report was written
};

/// Mean over the records of one table cell; n counts the records that had the figure.
struct CellMean {
  double ate_rmse_m = 0, ate_max_m = 0, correct_rate = 0, fps = 0, tracking_median_ms = 0, wall_seconds = 0;
  std::size_t n_runs = 0;  // records in the cell
  std::size_t n_ok = 0;    // runs that succeeded
  std::size_t n_ate = 0;   // ... and had an ATE
  std::size_t n_speed = 0; // ... and had fps and tracking time
  std::size_t n_wall = 0;  // ... and had a wall time
};
CellMean mean_of(const std::vector<const RunRecord*>& records);

struct TableOptions {
  std::vector<std::string> configs;  // column groups, in order
  bool peer = false;                 // add the peer column group (ATE RMSE, max, wall time)
  std::string peer_name = "peer";
};

/// The two Markdown tables: per scenario (mean over paths and seeds) and per scenario x path (mean over
/// seeds). Each column group = one configuration: ATE RMSE [cm], ATE max [cm], correct rate [%], fps,
/// tracking median [ms]. Rows keep the order in which scenarios and paths first appear in `records`.
std::string render_markdown_tables(const std::vector<RunRecord>& records, const TableOptions& options);

/// Each dynamic scenario's ATE RMSE over the static scenario's along the same path, per configuration: one row
/// per scenario x path and one over all paths. Sums over the (path, seed) pairs where both have an ATE. Empty
/// when there are no static runs.
std::string render_static_ratio_table(const std::vector<RunRecord>& records, const std::vector<std::string>& configs);

/// Final and live ATE per scenario x path and configuration, for runs where a large mover drags the pose:
/// mean and worst run's RMSE of each, and the dragged events summed over the runs, with tracking and Local BA
/// medians. Empty when no record has a live trajectory.
std::string render_live_table(const std::vector<RunRecord>& records, const std::vector<std::string>& configs);

/// Replaces the text between the marker lines <!-- BENCHMARK-TABLE:BEGIN --> and <!-- BENCHMARK-TABLE:END -->
/// in `document` with `generated`; throws InputError (naming `document_name`) when the markers are missing.
std::string replace_between_markers(const std::string& document, const std::string& generated,
                                    const std::string& document_name);
inline constexpr const char* kTableBeginMarker = "<!-- BENCHMARK-TABLE:BEGIN -->";
inline constexpr const char* kTableEndMarker = "<!-- BENCHMARK-TABLE:END -->";

/// Reads `file`, replaces its generated block, writes it back.
void update_benchmarks_md(const std::filesystem::path& file, const std::string& generated);

nlohmann::json to_json(const RunRecord& r);

}  // namespace varslam::report
