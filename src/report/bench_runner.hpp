#pragma once
// `varslam bench` in a function: plan the matrix, generate (or reuse) sequences, run every configuration as an
// isolated child process of the same binary, in parallel up to the core count, then write results.json,
// table.md, one report.html per run and index.html.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace varslam::report {

struct BenchOptions {
  std::vector<std::string> scenarios = {"static", "walking", "unknown_box", "obstructing_box", "balloon", "mixed"};
  std::vector<std::string> paths = {"rgbd_dataset_freiburg2_desk_with_person", "rgbd_dataset_freiburg3_sitting_static",
                                    "rgbd_bonn_crowd3"};
  std::vector<std::uint64_t> seeds = {1, 2};
  double seconds = 3.0;  // fits the 20-minute budget on 2 cores (measured, see BENCHMARKS.md)
  std::vector<std::string> configs = {"huber", "semantic", "kernel", "full"};
  std::size_t jobs = 0;  // 0 = number of cores
  std::filesystem::path out = "bench_out";
  std::filesystem::path cache_dir;         // generated sequences; empty = <out>/sequences
  bool reuse_sequences = true;             // false: regenerate even when a cached sequence matches
  std::vector<std::filesystem::path> real; // real dataset folders run with the same configurations
  std::string detector = "auto";           // auto (boxes where boxes.txt exists, else yolo) | boxes | yolo
  std::vector<std::string> extra_sets;     // more --set overrides for every run
  bool realtime = false;                   // pass --realtime to the runs
  double timeout_seconds = 0.0;            // > 0: a child running longer is killed and counted as failed
  std::string peer_template;               // shell command with {dataset} {settings} {out}
  std::string peer_trajectory = "CameraTrajectory.txt";
  std::string peer_name = "peer";
  std::filesystem::path update_markdown;   // BENCHMARKS.md to rewrite between markers
  std::filesystem::path trajectories_dir;  // where path names are looked up
  std::filesystem::path executable;        // the varslam binary for children; empty = /proc/self/exe
  std::function<void(const std::string&)> log;  // progress lines; empty = stdout
  std::string command_line;                // how the benchmark was invoked (recorded)
};

struct BenchOutcome {
  std::filesystem::path out;
  std::size_t runs = 0, failed = 0;
  double wall_seconds = 0.0;
  std::string table_markdown;
  nlohmann::json results;
};

/// Runs the whole benchmark. Throws InputError on bad options (unknown scenario/config, missing path, ...);
/// failed runs do not throw: they are recorded and shown as "fail" in the table.
BenchOutcome run_benchmark(const BenchOptions& options);

}  // namespace varslam::report
