// `varslam bench`: scenarios x paths x seeds x configurations, each run an isolated child process of this binary;
// and its three steps apart (plan, run-job / execute / jobs, collect) for executors other than the built-in one.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "report/bench_matrix.hpp"
#include "report/bench_collect.hpp"
#include "report/bench_job.hpp"
#include "report/bench_local_executor.hpp"
#include "report/bench_plan_file.hpp"
#include "report/bench_runner.hpp"
#include "report/bench_slurm.hpp"
#include "report/machine_info.hpp"
#include "report/process_pool.hpp"

namespace varslam::cli {
namespace {
namespace fs = std::filesystem;

// The shared camera paths: $VARSLAM_TRAJECTORIES, else ../shared/trajectories beside the source tree that
// holds this binary, else /work/shared/trajectories.
fs::path default_trajectories_dir() {
  if (const char* env = std::getenv("VARSLAM_TRAJECTORIES")) return env;
  std::error_code ec;
  for (fs::path dir = report::self_executable().parent_path(); !dir.empty(); dir = dir.parent_path()) {
    if (fs::exists(dir / ".git", ec) && fs::is_directory(dir.parent_path() / "shared" / "trajectories", ec))
      return dir.parent_path() / "shared" / "trajectories";
    if (dir == dir.parent_path()) break;
  }
  return "/work/shared/trajectories";
}

struct BenchCliOptions {
  report::BenchOptions b;
  std::string scenarios, paths, seeds, configs, trajectories, matrix = "default";
  std::vector<std::string> real;
  bool fresh = false;
};

void print_line(const std::string& line) {
  std::fputs((line + "\n").c_str(), stdout);
  std::fflush(stdout);
}

// The benchmark options from `bench`'s command line: a named matrix fills what the command line leaves out.
report::BenchOptions bench_options(BenchCliOptions& o, const CLI::App& cmd) {
  const report::NamedMatrix& matrix = report::matrix_by_name(o.matrix);
  if (cmd.count("--scenarios") == 0) o.scenarios = fmt::format("{}", fmt::join(matrix.scenarios, ","));
  if (cmd.count("--paths") == 0) o.paths = fmt::format("{}", fmt::join(matrix.paths, ","));
  if (cmd.count("--seeds") == 0) o.seeds = fmt::format("{}", fmt::join(matrix.seeds, ","));
  if (cmd.count("--configs") == 0) o.configs = fmt::format("{}", fmt::join(matrix.configs, ","));
  if (cmd.count("--seconds") == 0) o.b.seconds = matrix.seconds;
  report::BenchOptions b = o.b;
  b.scenarios = report::split_list(o.scenarios);
  b.paths = report::split_list(o.paths);
  b.configs = report::split_list(o.configs);
  b.seeds.clear();
  for (const auto& s : report::split_list(o.seeds)) {
    try {
      std::size_t used = 0;
      b.seeds.push_back(std::stoull(s, &used));
      if (used != s.size() || s.front() == '-') throw std::invalid_argument(s);
    } catch (const std::exception&) {
      throw InputError("bench: --seeds: '" + s + "' is not a non-negative integer");
    }
  }
  for (const auto& r : o.real) b.real.emplace_back(r);
  b.reuse_sequences = !o.fresh;
  b.trajectories_dir = o.trajectories.empty() ? default_trajectories_dir() : fs::path(o.trajectories);
  // The exact command that reproduces this benchmark (every option spelled out).
  std::vector<std::string> argv{"varslam", "bench", "--matrix", o.matrix, "--scenarios", o.scenarios, "--paths", o.paths,
                                "--seeds", o.seeds, "--seconds", fmt::format("{}", b.seconds), "--configs", o.configs,
                                "--detector", b.detector, "--out", b.out.string()};
  if (b.sensor != "default") argv.insert(argv.end(), {"--sensor", b.sensor});
  if (b.jobs) argv.insert(argv.end(), {"--jobs", std::to_string(b.jobs)});
  for (const auto& r : o.real) argv.insert(argv.end(), {"--real", r});
  for (const auto& s : b.extra_sets) argv.insert(argv.end(), {"--set", s});
  if (b.realtime) argv.emplace_back("--realtime");
  if (b.timeout_seconds > 0) argv.insert(argv.end(), {"--timeout", fmt::format("{}", b.timeout_seconds)});
  if (!b.peer_template.empty())
    argv.insert(argv.end(), {"--peer", b.peer_template, "--peer-trajectory", b.peer_trajectory, "--peer-name",
                             b.peer_name});
  b.command_line = report::shell_join(argv);
  b.log = print_line;
  return b;
}

// A job number from the command line: "-1" or "3x" is an error naming it, not a huge or truncated number.
std::size_t parse_job_number(const std::string& text) {
  std::size_t used = 0, n = 0;
  try {
    if (text.empty() || text.front() == '-' || text.front() == '+') throw std::invalid_argument(text);
    n = std::stoull(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size())
    throw InputError(fmt::format("bench run-job: job number '{}' is not a non-negative integer", text));
  return n;
}

// How to run a written plan with each executor, printed by `bench plan`.
void print_how_to_run(const report::BenchPlan& plan, bool slurm) {
  const std::string exe = report::shell_quote(plan.executable.string());
  const std::string dir = report::shell_quote(plan.dir.string());
  std::string stages;
  for (int s = 0; s < report::stage_count(plan); ++s) stages += (s ? " " : "") + std::to_string(s);
  print_line(fmt::format("run its jobs with one of (stages in order, a complete job is not run again):"));
  print_line(fmt::format("  {} bench execute {} -j 2", exe, dir));
  print_line(fmt::format("  for s in {}; do {} bench jobs {} --stage $s | parallel -j 2 {} bench run-job {}; done",
                         stages, exe, dir, exe, dir));
  print_line(fmt::format("  for s in {}; do {} bench jobs {} --stage $s | xargs -r -P 2 -n 1 {} bench run-job {}; done",
                         stages, exe, dir, exe, dir));
  if (slurm) print_line(fmt::format("  sh {}", report::shell_quote((plan.dir / "slurm" / "submit.sh").string())));
  print_line(fmt::format("then: {} bench collect {}", exe, dir));
}

void add_plan_command(CLI::App& bench, const std::shared_ptr<BenchCliOptions>& o) {
  auto* cmd = bench.add_subcommand("plan", "Write the benchmark as independent jobs into <--out>/plan.jsonl "
                                           "(docs/bench_plan.md) without running them; every bench option applies");
  cmd->fallthrough();  // the matrix options are bench's own: `bench plan --scenarios walking --out DIR`
  auto slurm = std::make_shared<bool>(false);
  cmd->add_flag("--slurm", *slurm, "Also write <--out>/slurm/stage<K>.sbatch (one job array per stage) and submit.sh");
  cmd->callback([o, slurm, &bench] {
    report::BenchOptions b = bench_options(*o, bench);
    const auto folder = report::claim_bench_folder(b.out);
    const report::BenchPlan plan = report::make_bench_plan(b);
    report::write_bench_plan(plan, !b.reuse_sequences);
    const std::size_t synth = report::jobs_of_stage(plan, 0).size();
    print_line(fmt::format("bench plan: {} jobs in {} stages ({} in stage 0) -> {}", plan.jobs.size(),
                           report::stage_count(plan), synth, plan.file().string()));
    if (*slurm) print_line("bench plan: Slurm scripts in " + report::write_slurm_scripts(plan).parent_path().string());
    print_how_to_run(plan, *slurm);
  });
}

void add_run_job_command(CLI::App& bench) {
  struct Args {
    std::string dir, number;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = bench.add_subcommand("run-job", "Run one job of a plan unless it is complete (exit 0: complete, "
                                              "1: the job failed and is recorded so)");
  cmd->add_option("dir", a->dir, "Plan folder (the --out of bench plan)")->required();
  cmd->add_option("job", a->number, "Job number (0 to jobs - 1)")->required();
  cmd->callback([a] {
    const report::BenchPlan plan = report::read_bench_plan(a->dir);
    const report::PlanJob& job = plan.job(parse_job_number(a->number));
    const report::JobMarker m = report::run_bench_job(plan, job.number, print_line);
    if (!m.ok)
      throw CommandFailed(fmt::format("bench run-job: {} failed: {}; log {}", report::describe_job(job), m.error,
                                      job.log_file.string()),
                          1);
    print_line(fmt::format("bench run-job: {} ok ({:.1f} s)", report::describe_job(job), m.wall_seconds));
  });
}

void add_jobs_command(CLI::App& bench) {
  struct Args {
    std::string dir;
    int stage = -1;
    bool missing = false;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = bench.add_subcommand("jobs", "Print a plan's job numbers, one a line, for an executor's input");
  cmd->add_option("dir", a->dir, "Plan folder")->required();
  cmd->add_option("--stage", a->stage, "Only this stage's jobs (run stage 0 before stage 1)")->check(CLI::NonNegativeNumber);
  cmd->add_flag("--missing", a->missing, "Only jobs that are not complete");
  cmd->callback([a] {
    const report::BenchPlan plan = report::read_bench_plan(a->dir);
    if (a->stage >= report::stage_count(plan))
      throw InputError(fmt::format("bench jobs: --stage {}: {} has stages 0 to {}", a->stage, plan.file().string(),
                                   report::stage_count(plan) - 1));
    for (const auto& job : plan.jobs) {
      if (a->stage >= 0 && job.stage != a->stage) continue;
      if (a->missing && report::job_state(plan, job) == report::JobState::Complete) continue;
      std::fputs(fmt::format("{}\n", job.number).c_str(), stdout);
    }
  });
}

void add_execute_command(CLI::App& bench) {
  struct Args {
    std::string dir;
    std::size_t jobs = 0;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = bench.add_subcommand("execute", "Run a plan's incomplete jobs with the built-in executor (child "
                                              "processes of this machine)");
  cmd->add_option("dir", a->dir, "Plan folder")->required();
  cmd->add_option("--jobs,-j", a->jobs, "Parallel child processes (default: number of cores)");
  cmd->callback([a] {
    const report::BenchPlan plan = report::read_bench_plan(a->dir);
    const auto t_start = std::chrono::steady_clock::now();
    const std::size_t parallel = a->jobs ? a->jobs : std::max(1u, report::sample_machine_info().cores);
    const report::LocalExecution e = report::execute_plan_locally(plan, parallel, print_line, [t_start] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    });
    print_line(fmt::format("bench execute: {} jobs run, {} failed; collect with: varslam bench collect {}", e.started,
                           e.failed, report::shell_quote(plan.dir.string())));
  });
}

void add_collect_command(CLI::App& bench) {
  struct Args {
    std::string dir;
    report::CollectOptions c;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = bench.add_subcommand("collect", "Write results.json, table.md and index.html of a plan from the jobs "
                                              "that ended, and name the missing ones (exit 5 when some are)");
  cmd->add_option("dir", a->dir, "Plan folder")->required();
  cmd->add_option("--update-benchmarks-md", a->c.update_markdown,
                  "Rewrite the generated table of this Markdown file (between its BENCHMARK-TABLE markers)")
      ->check(CLI::ExistingFile);
  cmd->callback([a] {
    const report::BenchPlan plan = report::read_bench_plan(a->dir);
    a->c.log = print_line;
    const report::BenchOutcome r = report::collect_benchmark(plan, a->c);
    if (!r.missing.empty())
      throw CommandFailed(fmt::format("bench collect: {} of {} jobs missing (listed above); run them and collect "
                                      "again", r.missing.size(), plan.jobs.size()),
                          kExitIncomplete);
  });
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto o = std::make_shared<BenchCliOptions>();
  const report::BenchOptions defaults;
  o->scenarios = fmt::format("{}", fmt::join(defaults.scenarios, ","));
  o->paths = fmt::format("{}", fmt::join(defaults.paths, ","));
  o->seeds = fmt::format("{}", fmt::join(defaults.seeds, ","));
  o->configs = fmt::format("{}", fmt::join(defaults.configs, ","));

  auto* cmd = app.add_subcommand(
      "bench", "Benchmark matrix: scenarios x camera paths x seeds x configurations (and real folders), run as "
               "parallel child processes; writes results.json, table.md, index.html and a report.html per run. "
               "= bench plan + bench execute + bench collect");
  cmd->require_subcommand(0, 1);
  std::string matrix_help = "Named matrix whose scenarios, paths, seeds, seconds and configurations are used "
                            "where those options are not given:";
  for (const auto& m : report::named_matrices()) matrix_help += fmt::format(" {} ({});", m.name, m.description);
  cmd->add_option("--matrix", o->matrix, matrix_help)->capture_default_str();
  cmd->add_option("--scenarios", o->scenarios, "Synthetic scenarios, comma separated (empty: none)")->capture_default_str();
  cmd->add_option("--paths", o->paths,
                  "Camera paths, comma separated: folder names under --trajectories, folders or TUM files; "
                  "NAME@SECONDS fixes the start (default: the window centred in the recording)")
      ->capture_default_str();
  cmd->add_option("--seeds", o->seeds, "Seeds, comma separated")->capture_default_str();
  cmd->add_option("--seconds", o->b.seconds, "Length of each synthetic sequence")
      ->capture_default_str()
      ->check(finite_range(0.0, 3600.0, true));
  cmd->add_option("--configs", o->configs, "Configurations: huber, semantic, kernel, full")->capture_default_str();
  cmd->add_option("--sensor", o->b.sensor, "Sensor of the synthetic sequences: default | kinect1 (varslam synth --sensor)")
      ->check(CLI::IsMember({"default", "kinect1"}))
      ->capture_default_str();
  cmd->add_option("--jobs,-j", o->b.jobs, "Parallel child processes (default: number of cores)");
  cmd->add_option("--out,-o", o->b.out, "Output folder")->capture_default_str()->check(kNonEmptyPath);
  cmd->add_option("--cache", o->b.cache_dir, "Folder of generated sequences, reusable across benchmarks "
                                             "(default: <out>/sequences)")
      ->check(kNonEmptyPath);
  cmd->add_flag("--fresh", o->fresh, "Regenerate sequences even when the cache has them");
  cmd->add_option("--real", o->real, "Real dataset folder (TUM/Bonn/OpenLORIS/7-Scenes layout), repeatable")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--detector", o->b.detector,
                  "Detector of the semantic configurations: auto (ground-truth boxes.txt where present, else "
                  "yolo), boxes, yolo")
      ->capture_default_str();
  cmd->add_option("--set", o->b.extra_sets, "Extra settings override for every run: section.key=value (repeatable)");
  cmd->add_option("--timeout", o->b.timeout_seconds, "Kill a child process after this many seconds (0: never)")
      ->capture_default_str()
      ->check(finite_range(0.0, 1e7));
  cmd->add_flag("--realtime", o->b.realtime, "Run SLAM in real-time mode (default: deterministic)");
  cmd->add_option("--peer", o->b.peer_template,
                  "Peer RGB-D SLAM command run on every sequence, with {dataset} {settings} {out} placeholders "
                  "(run through /bin/sh)");
  cmd->add_option("--peer-trajectory", o->b.peer_trajectory, "Trajectory file the peer writes into {out}")
      ->capture_default_str();
  cmd->add_option("--peer-name", o->b.peer_name, "Column name of the peer")->capture_default_str();
  cmd->add_option("--update-benchmarks-md", o->b.update_markdown,
                  "Rewrite the generated table of this Markdown file (between its BENCHMARK-TABLE markers)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--trajectories", o->trajectories, "Folder of camera paths (default: ../shared/trajectories)");


  add_plan_command(*cmd, o);
  add_run_job_command(*cmd);
  add_jobs_command(*cmd);
  add_execute_command(*cmd);
  add_collect_command(*cmd);

  cmd->callback([o, cmd] {
    if (!cmd->get_subcommands().empty()) return;  // one of the steps ran instead
    const report::BenchOutcome r = report::run_benchmark(bench_options(*o, *cmd));
    if (r.runs > 0 && r.failed == r.runs) throw InputError("bench: every run failed; see the logs under " + r.out.string());
  });
}

}  // namespace varslam::cli
