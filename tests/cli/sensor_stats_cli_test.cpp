// `varslam sensor-stats` as a user runs it: runs side by side, and clear errors for folders it cannot use.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_runner.hpp"

namespace varslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using cli_test::Outcome;
using cli_test::slurp;

Outcome sensor_cli(const std::string& args) { return cli_test::cli(args, "varslam_sensor_cli"); }

// A run folder holding `metrics` as its metrics.json (empty: no metrics.json at all).
fs::path run_folder(const std::string& name, const std::string& metrics) {
  const fs::path d = fs::temp_directory_path() / ("varslam_sensor_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  if (!metrics.empty()) std::ofstream(d / "metrics.json") << metrics;
  return d;
}

std::string metrics_with_reprojection(double median) {
  return nlohmann::json{
      {"frames", 10},
      {"sensor",
       {{"reprojection_px", {{"median", median}, {"p95", 2.0}}}, {"track_length", {{"median", 3}, {"points", 500}}}}}}
      .dump();
}

TEST(SensorStatsCli, PutsRunsSideBySideAndWritesThemAsJson) {
  const fs::path a = run_folder("a", metrics_with_reprojection(0.5));
  const fs::path b = run_folder("b", metrics_with_reprojection(0.875));
  const fs::path out = fs::temp_directory_path() / ("varslam_sensor_cli_" + std::to_string(::getpid()) + ".json");
  fs::remove(out);
  const Outcome o =
      sensor_cli("sensor-stats " + a.string() + " " + b.string() + " --names real,synth --out " + out.string());
  ASSERT_EQ(o.exit_code, 0) << o.output;
  EXPECT_THAT(o.output, HasSubstr("| statistic | real | synth |"));
  EXPECT_THAT(o.output, HasSubstr("median (px) | 0.500 | 0.875 |"));
  EXPECT_THAT(o.output, HasSubstr("| map points | 500 | 500 |"));
  const nlohmann::json j = nlohmann::json::parse(slurp(out));
  ASSERT_EQ(j.size(), 2u);
  EXPECT_EQ(j[1]["name"], "synth");
  EXPECT_EQ(j[1]["sensor"]["reprojection_px"]["median"].get<double>(), 0.875);
}

TEST(SensorStatsCli, ColumnsAreNamedAfterTheFoldersByDefault) {
  const fs::path a = run_folder("named", metrics_with_reprojection(0.5));
  const Outcome o = sensor_cli("sensor-stats " + a.string() + "/");
  ASSERT_EQ(o.exit_code, 0) << o.output;
  EXPECT_THAT(o.output, HasSubstr("| statistic | " + a.filename().string() + " |"));
}

TEST(SensorStatsCli, AMissingFolderIsAnErrorNamingIt) {
  const fs::path a = run_folder("exists", metrics_with_reprojection(0.5));
  const std::string missing = (fs::temp_directory_path() / "varslam_sensor_cli_no_such_run").string();
  const Outcome o = sensor_cli("sensor-stats " + a.string() + " " + missing);
  EXPECT_EQ(o.exit_code, 2) << o.output;
  EXPECT_THAT(o.output, HasSubstr(missing + ": no such run folder"));
}

TEST(SensorStatsCli, AFolderWithoutMetricsIsAnErrorNamingTheFile) {
  const fs::path a = run_folder("empty", "");
  const Outcome o = sensor_cli("sensor-stats " + a.string());
  EXPECT_EQ(o.exit_code, 2) << o.output;
  EXPECT_THAT(o.output, HasSubstr((a / "metrics.json").string() + ": missing"));
}

TEST(SensorStatsCli, MetricsWithoutTheSectionAreAnErrorNamingTheFile) {
  const fs::path a = run_folder("old", R"({"frames": 10, "tracked_frames": 10})");
  const Outcome o = sensor_cli("sensor-stats " + a.string());
  EXPECT_EQ(o.exit_code, 2) << o.output;
  EXPECT_THAT(o.output, HasSubstr((a / "metrics.json").string() + ": no \"sensor\" section"));
}

TEST(SensorStatsCli, BrokenMetricsAreAnErrorNamingTheFile) {
  const fs::path a = run_folder("broken", R"({"frames": 1)");
  const Outcome o = sensor_cli("sensor-stats " + a.string());
  EXPECT_EQ(o.exit_code, 2) << o.output;
  EXPECT_THAT(o.output, HasSubstr((a / "metrics.json").string() + ": not valid JSON"));
}

TEST(SensorStatsCli, NamesMustMatchTheRuns) {
  const fs::path a = run_folder("one", metrics_with_reprojection(0.5));
  const Outcome o = sensor_cli("sensor-stats " + a.string() + " --names x,y");
  EXPECT_EQ(o.exit_code, 2) << o.output;
  EXPECT_THAT(o.output, HasSubstr("--names gives 2 names for 1 run folders"));
}

}  // namespace
}  // namespace varslam
