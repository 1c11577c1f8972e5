// `varslam sensor-stats`: the scene-independent sensor statistics of several runs (metrics.json "sensor") side by
// side, to compare a synthetic sensor with a real one (issue #33).
#include <cstdio>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/file_problem.hpp"
#include "run/sensor_stats.hpp"

namespace varslam::cli {
namespace {

struct SensorStatsArgs {
  std::vector<std::string> runs;
  std::vector<std::string> names;
  std::string out;
};

// A column's name: the one given, else the run folder's own name.
std::vector<std::string> column_names(const SensorStatsArgs& a) {
  if (!a.names.empty() && a.names.size() != a.runs.size())
    throw InputError("--names gives " + std::to_string(a.names.size()) + " names for " + std::to_string(a.runs.size()) +
                     " run folders");
  if (!a.names.empty()) return a.names;
  std::vector<std::string> names;
  for (const std::filesystem::path p : a.runs) {
    const std::filesystem::path clean = p.lexically_normal();
    names.push_back(clean.has_filename() ? clean.filename().string() : clean.parent_path().filename().string());
  }
  return names;
}

void run_sensor_stats(const SensorStatsArgs& a) {
  if (!a.out.empty()) check_output_file(a.out, "sensor statistics");
  const std::vector<std::string> names = column_names(a);
  std::vector<nlohmann::json> sections;
  for (const std::string& run : a.runs) sections.push_back(run::read_sensor_section(run));
  std::fputs(run::sensor_table_markdown(names, sections).c_str(), stdout);
  if (a.out.empty()) return;
  nlohmann::json j = nlohmann::json::array();
  for (std::size_t i = 0; i < sections.size(); ++i)
    j.push_back({{"name", names[i]}, {"run", a.runs[i]}, {"sensor", sections[i]}});
  write_file_atomically(a.out, j.dump(2) + "\n", "sensor statistics");
  std::printf("wrote %s\n", a.out.c_str());
}

}  // namespace

void add_sensor_stats_command(CLI::App& app) {
  auto args = std::make_shared<SensorStatsArgs>();
  auto* cmd =
      app.add_subcommand("sensor-stats",
                         "Sensor statistics of runs side by side (metrics.json \"sensor\"): residuals after pose "
                         "optimisation, track lengths, depth consistency, keypoints with depth");
  cmd->add_option("runs", args->runs, "Run folders (each holding the metrics.json of a varslam run)")->required();
  cmd->add_option("--names", args->names, "Column names, comma-separated, one per run (default: folder names)")
      ->delimiter(',');
  cmd->add_option("--out", args->out, "Also write the statistics as JSON here")->check(kNonEmptyPath);
  cmd->callback([args] { run_sensor_stats(*args); });
}

}  // namespace varslam::cli
