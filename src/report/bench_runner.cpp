#include "report/bench_runner.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/output_folder.hpp"
#include "eval/ate.hpp"
#include "eval/drag_events.hpp"
#include "io/trajectory_io.hpp"
#include "report/bench_matrix.hpp"
#include "report/bench_results.hpp"
#include "report/bench_summary.hpp"
#include "report/machine_info.hpp"
#include "report/process_pool.hpp"
#include "report/run_report.hpp"

namespace varslam::report {
namespace fs = std::filesystem;
namespace {

constexpr const char* kCacheKeyFile = "bench_cache_key.txt";

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const fs::path& file, const std::string& text) { write_file_atomically(file, text, "benchmark file"); }

std::string now_iso8601() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// One planned child process and what it is for.
struct Planned {
  enum class Kind { Synth, Run, Peer } kind = Kind::Run;
  std::size_t sequence = 0;
  std::string config;     // for runs
  std::string detector;   // for semantic runs
  fs::path out_dir;       // run / peer output
  std::string shell;      // exact command for people
};

bool cached_sequence_matches(const SequenceSpec& s) {
  return fs::exists(s.dir / kCacheKeyFile) && fs::exists(s.dir / "groundtruth.txt") &&
         read_text(s.dir / kCacheKeyFile) == synth_cache_key(s);
}

// Peer template placeholders become shell-quoted paths; the command runs through /bin/sh.
std::string expand_peer_template(const std::string& tmpl, const SequenceSpec& seq, const fs::path& out_dir) {
  std::string s = tmpl;
  const std::vector<std::pair<std::string, std::string>> subs = {
      {"{dataset}", shell_quote(seq.dir.string())},
      {"{settings}", shell_quote((seq.dir / "settings.yaml").string())},
      {"{out}", shell_quote(out_dir.string())}};
  for (const auto& [key, value] : subs) {
    for (auto pos = s.find(key); pos != std::string::npos; pos = s.find(key, pos + value.size()))
      s.replace(pos, key.size(), value);
  }
  return s;
}

// ATE of the peer's trajectory against the sequence's ground truth, with our own evaluator.
RunFigures peer_figures(const SequenceSpec& seq, const fs::path& out_dir, const std::string& trajectory_name,
                        double wall_seconds, std::string& error) {
  const double nan = std::nan("");
  RunFigures f{nan, nan, nan, nan, nan, wall_seconds};
  const fs::path traj = out_dir / trajectory_name;
  if (!fs::exists(traj)) {
    error = traj.string() + ": the peer wrote no trajectory";
    return f;
  }
  try {
    const Trajectory est = read_tum_trajectory(traj);
    const Trajectory gt = read_tum_trajectory(seq.dir / "groundtruth.txt");
    const AteResult ate = evaluate_ate(gt, est);
    f.ate_rmse_m = ate.stats.rmse;
    f.ate_max_m = ate.stats.max;
    f.correct_rate = correct_rate(ate.stats.count, est.size());
    f.dragged_events = static_cast<double>(find_drag_events(gt, est).size());
    write_tum_trajectory(ate.aligned_estimate, out_dir / "CameraTrajectory_aligned.txt");
  } catch (const InputError& e) {
    error = e.what();
  }
  return f;
}

}  // namespace

BenchOutcome run_benchmark(const BenchOptions& o) {
  const auto log = [&o](const std::string& line) {
    if (o.log) o.log(line);
    else fmt::print("{}\n", line);
  };
  const auto t_start = std::chrono::steady_clock::now();
  const std::string started = now_iso8601();
  const MachineInfo machine_start = sample_machine_info();

  // ---- plan -------------------------------------------------------------------------------------------------
  if (!(o.seconds > 0)) throw InputError("bench: --seconds must be positive");
  for (const auto& c : o.configs) (void)configuration_by_name(c);
  if (o.configs.empty()) throw InputError("bench: no configuration given");
  if (o.detector != "auto" && o.detector != "boxes" && o.detector != "yolo")
    throw InputError("bench: --detector must be auto, boxes or yolo, got '" + o.detector + "'");
  const fs::path out = fs::absolute(o.out).lexically_normal();
  const fs::path cache = o.cache_dir.empty() ? out / "sequences" : fs::absolute(o.cache_dir).lexically_normal();
  // The summary files are the benchmark's own; each run folder is its run's (varslam run keeps its manifest).
  const OutputFolder out_folder(out, {{"results.json", "benchmark results"},
                                      {"table.md", "benchmark table"},
                                      {"index.html", "benchmark summary"}});
  fs::create_directories(cache);
  const fs::path exe = o.executable.empty() ? self_executable() : fs::absolute(o.executable);

  std::vector<CameraPathChoice> paths;
  if (!o.scenarios.empty())
    for (const auto& p : o.paths) paths.push_back(resolve_camera_path(p, o.trajectories_dir, o.seconds));
  std::vector<SequenceSpec> sequences =
      paths.empty() ? std::vector<SequenceSpec>{} : synthetic_sequences(o.scenarios, paths, o.seeds, o.seconds, cache);
  for (const auto& r : o.real) sequences.push_back(real_sequence(r));
  if (sequences.empty()) throw InputError("bench: nothing to run (no scenario x path and no --real folder)");

  std::vector<ProcessTask> tasks;
  std::vector<Planned> plan;
  std::vector<bool> reused(sequences.size(), false);
  for (std::size_t si = 0; si < sequences.size(); ++si) {
    const SequenceSpec& seq = sequences[si];
    std::vector<std::size_t> after;
    if (!seq.real) {
      if (o.reuse_sequences && cached_sequence_matches(seq)) {
        reused[si] = true;
      } else {
        // Only folders we generated are removed (synth marks its own with scenario.json, we add the key file).
        if (fs::exists(seq.dir)) {
          if (!fs::exists(seq.dir / kCacheKeyFile) && !fs::exists(seq.dir / "scenario.json"))
            throw InputError(seq.dir.string() + ": exists and is not a cached benchmark sequence; remove it");
          fs::remove_all(seq.dir);
        }
        std::vector<std::string> argv{exe.string()};
        for (auto& a : synth_arguments(seq)) argv.push_back(std::move(a));
        fs::create_directories(cache / "logs");
        tasks.push_back({argv, cache / "logs" / (seq.id + ".synth.log"), {}, o.timeout_seconds});
        plan.push_back({Planned::Kind::Synth, si, "", "", seq.dir, shell_join(argv)});
        after.push_back(tasks.size() - 1);
      }
    }
    for (const auto& config_name : o.configs) {
      const BenchConfiguration& config = configuration_by_name(config_name);
      std::string detector;
      fs::path boxes;
      if (config.semantic) {
        const bool has_boxes = !seq.real || fs::exists(seq.dir / "boxes.txt");
        detector = o.detector == "auto" ? (has_boxes ? "boxes" : "yolo") : o.detector;
        if (detector == "boxes") {
          if (!has_boxes)
            throw InputError(seq.dir.string() + ": no boxes.txt for --detector boxes (use --detector yolo or auto)");
          boxes = seq.dir / "boxes.txt";
        }
      }
      const fs::path run_dir = out / "runs" / seq.id / config_name;
      fs::create_directories(run_dir);
      // A run that tracks little is a result here (its ATE and tracked share go into the table), not a failure.
      std::vector<std::string> argv{exe.string(), "run", "--dataset", seq.dir.string(), "--out", run_dir.string(), "-q",
                                    "--min-tracked-share", "0"};
      if (o.realtime) argv.emplace_back("--realtime");
      for (const auto& s : configuration_overrides(config, detector, boxes)) {
        argv.emplace_back("--set");
        argv.push_back(s);
      }
      for (const auto& s : o.extra_sets) {
        argv.emplace_back("--set");
        argv.push_back(s);
      }
      // A stale metrics.json from an earlier benchmark must not pass for this run's result (a run that fails
      // before it starts leaves the earlier one's files otherwise).
      remove_earlier_outputs(run_dir);
      tasks.push_back({argv, run_dir / "run.log", after, o.timeout_seconds});
      plan.push_back({Planned::Kind::Run, si, config_name, detector, run_dir, shell_join(argv)});
    }
    if (!o.peer_template.empty()) {
      const fs::path peer_dir = out / "peer" / seq.id;
      fs::create_directories(peer_dir);
      fs::remove(peer_dir / o.peer_trajectory);
      const std::string cmd = expand_peer_template(o.peer_template, seq, peer_dir);
      tasks.push_back({{"/bin/sh", "-c", cmd}, peer_dir / "peer.log", after, o.timeout_seconds});
      plan.push_back({Planned::Kind::Peer, si, "peer", "", peer_dir, cmd});
    }
  }

  const std::size_t jobs = o.jobs ? o.jobs : std::max(1u, machine_start.cores);
  std::size_t n_synth = 0;
  for (const auto& p : plan) n_synth += p.kind == Planned::Kind::Synth;
  log(fmt::format("bench: {} sequences ({} to generate, {} cached), {} configurations, {} child processes, {} at a "
                  "time -> {}",
                  sequences.size(), n_synth, std::count(reused.begin(), reused.end(), true), o.configs.size(),
                  tasks.size(), jobs, out.string()));

  // ---- execute ----------------------------------------------------------------------------------------------
  std::vector<RunRecord> records;
  std::vector<nlohmann::json> run_json, seq_json(sequences.size());
  std::map<std::size_t, double> synth_seconds;
  const auto progress = [&](std::size_t i, const ProcessOutcome& outcome, std::size_t done) {
    const Planned& p = plan[i];
    const SequenceSpec& seq = sequences[p.sequence];
    const bool ok = outcome.state == ProcessOutcome::State::Succeeded;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    std::string what;
    if (p.kind == Planned::Kind::Synth) {
      if (ok) write_text(seq.dir / kCacheKeyFile, synth_cache_key(seq));
      synth_seconds[p.sequence] = outcome.wall_seconds;
      what = fmt::format("synth {}", seq.id);
    } else {
      RunRecord r;
      r.sequence_id = seq.id;
      r.scenario = seq.scenario;
      r.path_name = seq.path_name;
      r.seed = seq.seed;
      r.config = p.config;
      r.run_dir = p.out_dir;
      r.ok = ok;
      r.error = outcome.error;
      nlohmann::json metrics;
      if (p.kind == Planned::Kind::Run) {
        if (ok && fs::exists(p.out_dir / "metrics.json")) {
          try {
            metrics = nlohmann::json::parse(read_text(p.out_dir / "metrics.json"));
          } catch (const nlohmann::json::exception& e) {
            r.ok = false;
            r.error = "metrics.json unreadable: " + std::string(e.what());
          }
          r.figures = figures_from_metrics(metrics);
          try {
            write_run_report(p.out_dir, seq.dir, p.out_dir / "report.html");
            r.report_html = p.out_dir / "report.html";
          } catch (const InputError& e) {
            log(fmt::format("bench: report for {} failed: {}", p.out_dir.string(), e.what()));
          }
        } else if (ok) {
          r.ok = false;
          r.error = "the run wrote no metrics.json";
        }
      } else {
        std::string err;
        if (ok) r.figures = peer_figures(seq, p.out_dir, o.peer_trajectory, outcome.wall_seconds, err);
        if (!err.empty()) r.error = err;
      }
      if (!std::isfinite(r.figures.wall_seconds)) r.figures.wall_seconds = outcome.wall_seconds;
      what = fmt::format("{} {} {}", p.kind == Planned::Kind::Peer ? o.peer_name : "run", seq.id, p.config);
      if (r.ok && std::isfinite(r.figures.ate_rmse_m))
        what += fmt::format("  ATE {:.2f} cm", 100.0 * r.figures.ate_rmse_m);
      nlohmann::json j = to_json(r);
      j["command"] = p.shell;
      j["exit_code"] = outcome.exit_code;
      j["process_wall_seconds"] = outcome.wall_seconds;
      if (!p.detector.empty()) j["detector"] = p.detector;
      if (p.kind == Planned::Kind::Run) j["metrics"] = metrics;
      run_json.push_back(std::move(j));
      records.push_back(std::move(r));
    }
    const char* state = ok ? "ok" : (outcome.state == ProcessOutcome::State::Skipped ? "SKIPPED" : "FAILED");
    log(fmt::format("[{}/{}] {:>6.0f} s  {} {} ({:.1f} s){}", done, tasks.size(), elapsed, what, state,
                    outcome.wall_seconds, ok ? "" : "  " + outcome.error + ", log " + tasks[i].log_file.string()));
  };
  const std::vector<ProcessOutcome> outcomes = run_processes(tasks, jobs, progress);

  // Records in plan order (completion order depends on timing), so tables and JSON are stable.
  std::vector<RunRecord> ordered;
  std::vector<nlohmann::json> ordered_json;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    if (plan[i].kind == Planned::Kind::Synth) continue;
    for (std::size_t k = 0; k < records.size(); ++k) {
      if (records[k].run_dir == plan[i].out_dir) {
        ordered.push_back(records[k]);
        ordered_json.push_back(run_json[k]);
      }
    }
  }

  // ---- write ------------------------------------------------------------------------------------------------
  BenchOutcome result;
  result.out = out;
  result.runs = ordered.size();
  for (const auto& r : ordered) result.failed += !r.ok;
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();

  TableOptions topt;
  topt.configs = o.configs;
  topt.peer = !o.peer_template.empty();
  topt.peer_name = o.peer_name;
  result.table_markdown = render_markdown_tables(ordered, topt);

  const MachineInfo machine_end = sample_machine_info();
  const std::string version = git_describe(exe.parent_path());
  for (std::size_t si = 0; si < sequences.size(); ++si) {
    const SequenceSpec& s = sequences[si];
    nlohmann::json j = {{"id", s.id}, {"scenario", s.scenario}, {"path", s.path_name}, {"dir", s.dir.string()},
                        {"real", s.real}};
    if (!s.real) {
      std::vector<std::string> argv{exe.string()};
      for (auto& a : synth_arguments(s)) argv.push_back(std::move(a));
      j.update({{"path_file", s.path_file.string()}, {"path_start_s", s.path_start}, {"seed", s.seed},
                {"seconds", s.seconds}, {"cached", reused[si]}, {"command", shell_join(argv)}});
      if (synth_seconds.count(si)) j["synth_wall_seconds"] = synth_seconds[si];
    }
    seq_json[si] = std::move(j);
  }
  nlohmann::json configs = nlohmann::json::array();
  for (const auto& c : o.configs) {
    const auto& bc = configuration_by_name(c);
    configs.push_back({{"name", bc.name}, {"description", bc.description},
                       {"overrides", configuration_overrides(bc, bc.semantic ? "boxes" : "", "<sequence>/boxes.txt")}});
  }
  result.results = {
      {"tool", "varslam bench"},
      {"version", {{"git_describe", version}, {"executable", exe.string()}}},
      {"command_line", o.command_line},
      {"started_utc", started},
      {"wall_seconds", result.wall_seconds},
      {"machine", to_json(machine_start)},
      {"load_average_1min_at_end", machine_end.load_average},
      {"options",
       {{"scenarios", o.scenarios}, {"paths", o.paths}, {"seeds", o.seeds}, {"seconds", o.seconds},
        {"configs", o.configs}, {"jobs", jobs}, {"detector", o.detector}, {"realtime", o.realtime},
        {"extra_sets", o.extra_sets}, {"timeout_seconds", o.timeout_seconds}, {"peer_template", o.peer_template}, {"peer_trajectory", o.peer_trajectory},
        {"cache_dir", cache.string()}}},
      {"configurations", configs},
      {"sequences", seq_json},
      {"runs", ordered_json},
      {"failed_runs", result.failed},
      {"table_markdown", result.table_markdown}};

  write_text(out / "results.json", result.results.dump(1) + "\n");
  const std::string header =
      fmt::format("Benchmark {} ({}), {} runs ({} failed) in {:.0f} s on {}; load average {:.1f} at the start.\n\n",
                  version, started, result.runs, result.failed, result.wall_seconds, describe(machine_start),
                  machine_start.load_average);
  write_text(out / "table.md", header + result.table_markdown);
  write_text(out / "index.html", render_bench_summary_html(result.results, ordered, topt, out));
  if (!o.update_markdown.empty()) {
    const std::string reproduce = "Reproduce: `" + o.command_line + "`\n\n";
    update_benchmarks_md(o.update_markdown, header + reproduce + result.table_markdown);
    log("bench: updated " + o.update_markdown.string());
  }
  log(fmt::format("bench: {} runs, {} failed, {:.0f} s; wrote {}/results.json, table.md, index.html", result.runs,
                  result.failed, result.wall_seconds, out.string()));
  (void)outcomes;
  return result;
}

}  // namespace varslam::report
