#pragma once
// A benchmark as a plan of independent jobs (written to <out>/plan.jsonl by bench_plan_file), so that any
// executor (the built-in process pool, GNU parallel, xargs, a Slurm job array) can run the jobs and
// `varslam bench collect` can gather whatever finished. Planning decides; it runs nothing.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "report/bench_matrix.hpp"

namespace varslam::report {

/// The options of `varslam bench`: what to plan, and how the built-in executor and the collection behave.
struct BenchOptions {
  std::vector<std::string> scenarios = {"static", "walking", "unknown_box", "obstructing_box", "balloon", "mixed"};
  std::vector<std::string> paths = {"rgbd_dataset_freiburg2_desk_with_person", "rgbd_dataset_freiburg3_sitting_static",
                                    "rgbd_bonn_crowd3"};
  std::vector<std::uint64_t> seeds = {1, 2};
  double seconds = 3.0;  // fits the 20-minute budget on 2 cores (measured, see BENCHMARKS.md)
  std::string sensor = "default";  // the synthetic sequences' sensor (`varslam synth --sensor`)
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

/// The plan's file in its folder (format: bench_plan_file.hpp, docs/bench_plan.md).
inline constexpr const char* kBenchPlanFile = "plan.jsonl";

/// One job: one child process with its output folder, what it needs first, and what a scheduler should grant it.
struct PlanJob {
  enum class Kind { Synth, Run, Peer };
  std::size_t number = 0;
  Kind kind = Kind::Run;
  std::string sequence;               // SequenceSpec::id
  std::string config;                 // configuration name, "peer", or empty (synth)
  std::string detector;               // semantic runs: boxes | yolo
  std::vector<std::string> argv;      // the exact command (argv[0] an absolute path)
  std::string command;                // the same for people and results.json
  std::filesystem::path out_dir;      // its outputs and its completion marker
  std::filesystem::path log_file;     // the command's stdout and stderr
  std::vector<std::size_t> needs;     // jobs whose outputs it reads (they come earlier in the plan)
  int stage = 0;                      // 0 needs nothing; 1 needs stage-0 jobs
  double timeout_seconds = 0.0;       // > 0: killed after this long (run-job enforces it)
  double time_limit_seconds = 0.0;    // what a scheduler should allow (Slurm --time)
  int memory_mb = 0;                  // what a scheduler should reserve (Slurm --mem)
};
std::string kind_name(PlanJob::Kind kind);

/// The whole plan: where, with which binary, the sequences, and the jobs in execution order.
struct BenchPlan {
  std::string id;                       // unique per planning: the markers this plan's jobs wrote name it
  std::string created_utc;
  std::filesystem::path dir;            // the plan folder (bench --out)
  std::filesystem::path executable;
  std::string git_describe;
  std::string command_line;
  nlohmann::json machine;               // MachineInfo where it was planned
  nlohmann::json options;               // the benchmark's options, as results.json records them
  std::vector<std::string> configs;     // table column groups, in order
  bool peer = false;
  std::string peer_name = "peer", peer_trajectory = "CameraTrajectory.txt";
  std::vector<SequenceSpec> sequences;  // synthetic and real, in table order
  std::vector<PlanJob> jobs;

  const SequenceSpec& sequence(const std::string& id) const;
  /// InputError naming the plan file and the valid range when `number` is not a job of this plan.
  const PlanJob& job(std::size_t number) const;
  std::filesystem::path file() const { return dir / kBenchPlanFile; }
};

/// Decides the plan from the options: resolves camera paths, validates configurations and folders, builds one
/// synth job per synthetic sequence and one run (and peer) job per sequence x configuration. Writes nothing.
/// Throws InputError on bad options.
BenchPlan make_bench_plan(const BenchOptions& options);

/// The plan's jobs of one stage, in order (an executor runs stage 0 before stage 1).
std::vector<std::size_t> jobs_of_stage(const BenchPlan& plan, int stage);
int stage_count(const BenchPlan& plan);

}  // namespace varslam::report
