// `varslam bench` end to end on a tiny matrix: real child processes of the built CLI (synth, run, a fake peer).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "report/bench_results.hpp"
#include "report/process_pool.hpp"
#include "file_text.hpp"

namespace varslam::report {
namespace {
namespace fs = std::filesystem;

using test::slurp;

TEST(BenchEndToEnd, TinyMatrixWritesResultsTablesReportsAndUpdatesMarkdown) {
  const fs::path cli = fs::path(VARSLAM_BINARY_DIR) / "bin" / "varslam";
  if (!fs::exists(cli)) GTEST_SKIP() << cli << " not built (build the varslam_cli target first)";
  const fs::path path = fs::path(VARSLAM_SHARED_DIR) / "trajectories" / "rgbd_dataset_freiburg3_sitting_static";
  if (!fs::exists(path)) GTEST_SKIP() << "camera path " << path << " not found (../shared is absent)";
  const fs::path out = fs::temp_directory_path() / "varslam_bench_e2e";
  fs::remove_all(out);
  fs::create_directories(out);
  const fs::path md = out / "BENCHMARKS.md";
  std::ofstream(md) << "# Benchmarks\n" << kTableBeginMarker << "\n(old)\n" << kTableEndMarker << "\nkept\n";

  // The fake peer copies the ground truth as its trajectory: its ATE must come out as exactly 0.
  const std::string cmd = shell_join({cli.string(), "bench", "--scenarios", "walking", "--paths",
                                      path.string(),
                                      "--seeds", "1", "--seconds", "1", "--configs", "huber,full", "--jobs", "2",
                                      "--out", (out / "bench").string(), "--peer",
                                      "cp {dataset}/groundtruth.txt {out}/peer_traj.txt", "--peer-trajectory",
                                      "peer_traj.txt", "--update-benchmarks-md", md.string()}) +
                          " > " + (out / "bench.log").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(out / "bench.log");

  const auto results = nlohmann::json::parse(slurp(out / "bench" / "results.json"));
  ASSERT_EQ(results["runs"].size(), 3u);  // huber, full, peer
  EXPECT_EQ(results["failed_runs"], 0);
  EXPECT_EQ(results["sequences"].size(), 1u);
  EXPECT_EQ(results["sequences"][0]["seed"], 1);
  EXPECT_NE(results["sequences"][0]["command"].get<std::string>().find(" synth "), std::string::npos);
  EXPECT_TRUE(results["machine"]["nproc"].get<int>() >= 1);
  EXPECT_FALSE(results["version"]["git_describe"].get<std::string>().empty());
  for (const auto& run : results["runs"]) {
    EXPECT_TRUE(run["ok"].get<bool>()) << run.dump();
    ASSERT_TRUE(run["ate_rmse_m"].is_number()) << run.dump();
    if (run["config"] == "peer") {
      EXPECT_NEAR(run["ate_rmse_m"].get<double>(), 0.0, 1e-6);
    } else {
      EXPECT_NE(run["command"].get<std::string>().find(" run --dataset "), std::string::npos);
      EXPECT_TRUE(run["metrics"].contains("timings"));
      EXPECT_TRUE(fs::exists(run["report"].get<std::string>())) << run.dump();
    }
  }
  const std::string table = slurp(out / "bench" / "table.md");
  EXPECT_NE(table.find("| scenario | huber RMSE |"), std::string::npos) << table;
  EXPECT_NE(table.find("| full RMSE |"), std::string::npos) << table;
  EXPECT_NE(table.find("| peer RMSE | peer max | peer s |"), std::string::npos) << table;
  EXPECT_NE(table.find("\n| walking | "), std::string::npos) << table;
  EXPECT_NE(table.find("\n| walking | fr3_sitting_static | "), std::string::npos) << table;
  EXPECT_EQ(table.find("| fail"), std::string::npos) << table;
  const std::string index = slurp(out / "bench" / "index.html");
  EXPECT_NE(index.find("/huber/report.html\""), std::string::npos);
  const std::string updated = slurp(md);
  EXPECT_NE(updated.find("| walking | fr3_sitting_static | "), std::string::npos) << updated;
  EXPECT_EQ(updated.find("(old)"), std::string::npos);
  EXPECT_NE(updated.find("kept"), std::string::npos);

  // Second invocation reuses the generated sequence.
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(out / "bench.log");
  const auto again = nlohmann::json::parse(slurp(out / "bench" / "results.json"));
  EXPECT_TRUE(again["sequences"][0]["cached"].get<bool>());
  fs::remove_all(out);
}

}  // namespace
}  // namespace varslam::report
