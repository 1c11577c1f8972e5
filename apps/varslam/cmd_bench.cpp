// `varslam bench`: scenarios x paths x seeds x configurations, each run an isolated child process of this binary.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstdio>
#include <cstdlib>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "report/bench_matrix.hpp"
#include "report/bench_runner.hpp"
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

}  // namespace

void add_bench_command(CLI::App& app) {
  struct Opts {
    report::BenchOptions b;
    std::string scenarios, paths, seeds, configs, trajectories, matrix = "default";
    std::vector<std::string> real;
    bool fresh = false;
  };
  auto o = std::make_shared<Opts>();
  const report::BenchOptions defaults;
  o->scenarios = fmt::format("{}", fmt::join(defaults.scenarios, ","));
  o->paths = fmt::format("{}", fmt::join(defaults.paths, ","));
  o->seeds = fmt::format("{}", fmt::join(defaults.seeds, ","));
  o->configs = fmt::format("{}", fmt::join(defaults.configs, ","));

  auto* cmd = app.add_subcommand(
      "bench", "Benchmark matrix: scenarios x camera paths x seeds x configurations (and real folders), run as "
               "parallel child processes; writes results.json, table.md, index.html and a report.html per run");
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

  cmd->callback([o, cmd] {
    // A named matrix fills what the command line leaves out.
    const report::NamedMatrix& matrix = report::matrix_by_name(o->matrix);
    if (cmd->count("--scenarios") == 0) o->scenarios = fmt::format("{}", fmt::join(matrix.scenarios, ","));
    if (cmd->count("--paths") == 0) o->paths = fmt::format("{}", fmt::join(matrix.paths, ","));
    if (cmd->count("--seeds") == 0) o->seeds = fmt::format("{}", fmt::join(matrix.seeds, ","));
    if (cmd->count("--configs") == 0) o->configs = fmt::format("{}", fmt::join(matrix.configs, ","));
    if (cmd->count("--seconds") == 0) o->b.seconds = matrix.seconds;
    report::BenchOptions b = o->b;
    b.scenarios = report::split_list(o->scenarios);
    b.paths = report::split_list(o->paths);
    b.configs = report::split_list(o->configs);
    b.seeds.clear();
    for (const auto& s : report::split_list(o->seeds)) {
      try {
        std::size_t used = 0;
        b.seeds.push_back(std::stoull(s, &used));
        if (used != s.size()) throw std::invalid_argument(s);
      } catch (const std::exception&) {
        throw InputError("bench: --seeds: '" + s + "' is not a non-negative integer");
      }
    }
    for (const auto& r : o->real) b.real.emplace_back(r);
    b.reuse_sequences = !o->fresh;
    b.trajectories_dir = o->trajectories.empty() ? default_trajectories_dir() : fs::path(o->trajectories);
    // The exact command that reproduces this benchmark (every option spelled out).
    std::vector<std::string> argv{"varslam", "bench", "--matrix", o->matrix, "--scenarios", o->scenarios, "--paths", o->paths, "--seeds",
                                  o->seeds, "--seconds", fmt::format("{}", b.seconds), "--configs", o->configs,
                                  "--detector", b.detector, "--out", b.out.string()};
    if (b.jobs) argv.insert(argv.end(), {"--jobs", std::to_string(b.jobs)});
    for (const auto& r : o->real) argv.insert(argv.end(), {"--real", r});
    for (const auto& s : b.extra_sets) argv.insert(argv.end(), {"--set", s});
    if (b.realtime) argv.emplace_back("--realtime");
    if (b.timeout_seconds > 0) argv.insert(argv.end(), {"--timeout", fmt::format("{}", b.timeout_seconds)});
    if (!b.peer_template.empty())
      argv.insert(argv.end(), {"--peer", b.peer_template, "--peer-trajectory", b.peer_trajectory, "--peer-name",
                               b.peer_name});
    b.command_line = report::shell_join(argv);
    b.log = [](const std::string& line) {
      std::fputs((line + "\n").c_str(), stdout);
      std::fflush(stdout);
    };
    const report::BenchOutcome r = report::run_benchmark(b);
    if (r.runs > 0 && r.failed == r.runs) throw InputError("bench: every run failed; see the logs under " + r.out.string());
  });
}

}  // namespace varslam::cli
