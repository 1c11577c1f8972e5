#include "report/bench_plan.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <unistd.h>

#include "core/error.hpp"
#include "report/bench_files.hpp"
#include "report/bench_job.hpp"
#include "report/machine_info.hpp"
#include "report/process_pool.hpp"

namespace varslam::report {
namespace fs = std::filesystem;
namespace {

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

// What a scheduler should grant a job. Measured on this project's 2-core machine (BENCHMARKS.md): synth takes
// ~8 s of wall time per second of sequence, a run ~3 s; the limits are four times that plus two minutes, so a
// slower node does not kill a healthy job. A real folder's length is not known here: an hour. A --timeout
// bounds the job itself, so the limit is that plus a minute to write the report.
void set_resources(PlanJob& job, const SequenceSpec& seq, double timeout_seconds) {
  const double per_second = job.kind == PlanJob::Kind::Synth ? 8.0 : 3.0;
  job.time_limit_seconds = seq.real ? 3600.0 : 120.0 + 4.0 * per_second * seq.seconds;
  if (timeout_seconds > 0) job.time_limit_seconds = timeout_seconds + 60.0;
  // Peak resident memory of a 3-s synth is ~0.3 GB and of a run ~0.5 GB (YOLO loaded); twice that and more.
  job.memory_mb = job.kind == PlanJob::Kind::Synth ? 1024 : 2048;
}

std::vector<std::string> run_arguments(const BenchOptions& o, const fs::path& exe, const SequenceSpec& seq,
                                       const BenchConfiguration& config, const std::string& detector,
                                       const fs::path& boxes, const fs::path& run_dir) {
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
  return argv;
}

// The detector a semantic configuration uses on `seq`: --detector, or for auto the ground-truth boxes where the
// sequence has them and YOLO elsewhere. Empty for configurations without a detector.
std::string detector_for(const BenchOptions& o, const BenchConfiguration& config, const SequenceSpec& seq,
                         fs::path& boxes) {
  if (!config.semantic) return "";
  const bool has_boxes = !seq.real || fs::exists(seq.dir / "boxes.txt");
  const std::string detector = o.detector == "auto" ? (has_boxes ? "boxes" : "yolo") : o.detector;
  if (detector == "boxes") {
    if (!has_boxes)
      throw InputError(seq.dir.string() + ": no boxes.txt for --detector boxes (use --detector yolo or auto)");
    boxes = seq.dir / "boxes.txt";
  }
  return detector;
}

void validate_options(const BenchOptions& o) {
  if (!(o.seconds > 0)) throw InputError("bench: --seconds must be positive");
  for (const auto& c : o.configs) (void)configuration_by_name(c);
  if (o.configs.empty()) throw InputError("bench: no configuration given");
  if (o.detector != "auto" && o.detector != "boxes" && o.detector != "yolo")
    throw InputError("bench: --detector must be auto, boxes or yolo, got '" + o.detector + "'");
}

std::vector<SequenceSpec> plan_sequences(const BenchOptions& o, const fs::path& cache) {
  std::vector<CameraPathChoice> paths;
  if (!o.scenarios.empty())
    for (const auto& p : o.paths) paths.push_back(resolve_camera_path(p, o.trajectories_dir, o.seconds));
  std::vector<SequenceSpec> sequences =
      paths.empty() ? std::vector<SequenceSpec>{} : synthetic_sequences(o.scenarios, paths, o.seeds, o.seconds, cache, o.sensor);
  for (const auto& r : o.real) sequences.push_back(real_sequence(r));
  if (sequences.empty()) throw InputError("bench: nothing to run (no scenario x path and no --real folder)");
  for (const auto& seq : sequences) {
    if (!seq.real && fs::exists(seq.dir) && !generated_by_bench(seq.dir))
      throw InputError(seq.dir.string() + ": exists and is not a cached benchmark sequence; remove it");
  }
  return sequences;
}

nlohmann::json options_json(const BenchOptions& o, const fs::path& cache) {
  return {{"scenarios", o.scenarios},       {"paths", o.paths},
          {"seeds", o.seeds},               {"seconds", o.seconds},
          {"configs", o.configs},           {"jobs", o.jobs},
          {"detector", o.detector},         {"realtime", o.realtime},
          {"extra_sets", o.extra_sets},     {"timeout_seconds", o.timeout_seconds},
          {"peer_template", o.peer_template}, {"peer_trajectory", o.peer_trajectory},
          {"cache_dir", cache.string()}};
}

std::string new_plan_id(const std::string& created_utc) {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count();
  return fmt::format("{}-{}-{}", created_utc, ::getpid(), ns % 1000000000);
}

// Appends the job with its number, stage (one after the latest it needs) and scheduler resources.
std::size_t add_job(BenchPlan& p, PlanJob job, double timeout_seconds) {
  job.number = p.jobs.size();
  job.timeout_seconds = timeout_seconds;
  for (const auto n : job.needs) job.stage = std::max(job.stage, p.jobs[n].stage + 1);
  set_resources(job, p.sequence(job.sequence), timeout_seconds);
  p.jobs.push_back(std::move(job));
  return p.jobs.back().number;
}

PlanJob synth_job(const BenchPlan& p, const SequenceSpec& seq, const fs::path& cache) {
  PlanJob job;
  job.kind = PlanJob::Kind::Synth;
  job.sequence = seq.id;
  job.argv = {p.executable.string()};
  for (auto& a : synth_arguments(seq)) job.argv.push_back(std::move(a));
  job.command = shell_join(job.argv);
  job.out_dir = seq.dir;
  job.log_file = cache / "logs" / (seq.id + ".synth.log");
  return job;
}

PlanJob run_job(const BenchPlan& p, const BenchOptions& o, const SequenceSpec& seq, const BenchConfiguration& config,
                const std::vector<std::size_t>& needs) {
  PlanJob job;
  job.kind = PlanJob::Kind::Run;
  job.sequence = seq.id;
  job.config = config.name;
  fs::path boxes;
  job.detector = detector_for(o, config, seq, boxes);
  job.out_dir = p.dir / "runs" / seq.id / config.name;
  job.argv = run_arguments(o, p.executable, seq, config, job.detector, boxes, job.out_dir);
  job.command = shell_join(job.argv);
  job.log_file = job.out_dir / "run.log";
  job.needs = needs;
  return job;
}

PlanJob peer_job(const BenchPlan& p, const std::string& peer_template, const SequenceSpec& seq,
                 const std::vector<std::size_t>& needs) {
  PlanJob job;
  job.kind = PlanJob::Kind::Peer;
  job.sequence = seq.id;
  job.config = "peer";
  job.out_dir = p.dir / "peer" / seq.id;
  job.command = expand_peer_template(peer_template, seq, job.out_dir);
  job.argv = {"/bin/sh", "-c", job.command};
  job.log_file = job.out_dir / "peer.log";
  job.needs = needs;
  return job;
}

}  // namespace

std::string kind_name(PlanJob::Kind kind) {
  switch (kind) {
    case PlanJob::Kind::Synth: return "synth";
    case PlanJob::Kind::Run: return "run";
    case PlanJob::Kind::Peer: return "peer";
  }
  return "?";
}

const SequenceSpec& BenchPlan::sequence(const std::string& sequence_id) const {
  for (const auto& s : sequences)
    if (s.id == sequence_id) return s;
  throw InputError(fmt::format("{}: no sequence '{}' in the plan's header", file().string(), sequence_id));
}

const PlanJob& BenchPlan::job(std::size_t number) const {
  if (number >= jobs.size())
    throw InputError(fmt::format("job {}: {} has {} jobs, numbered 0 to {}", number, file().string(), jobs.size(),
                                 jobs.empty() ? 0 : jobs.size() - 1));
  return jobs[number];
}

BenchPlan make_bench_plan(const BenchOptions& o) {
  validate_options(o);
  BenchPlan p;
  p.dir = fs::absolute(o.out).lexically_normal();
  const fs::path cache = o.cache_dir.empty() ? p.dir / "sequences" : fs::absolute(o.cache_dir).lexically_normal();
  p.executable = o.executable.empty() ? self_executable() : fs::absolute(o.executable);
  p.created_utc = utc_now_iso8601();
  p.id = new_plan_id(p.created_utc);
  p.git_describe = git_describe(p.executable.parent_path());
  p.command_line = o.command_line;
  p.machine = to_json(sample_machine_info());
  p.options = options_json(o, cache);
  p.configs = o.configs;
  p.peer = !o.peer_template.empty();
  p.peer_name = o.peer_name;
  p.peer_trajectory = o.peer_trajectory;
  p.sequences = plan_sequences(o, cache);

  // Sequences first: every synth job is in stage 0, every job reading a sequence after it.
  std::vector<std::vector<std::size_t>> needs(p.sequences.size());
  for (std::size_t si = 0; si < p.sequences.size(); ++si)
    if (!p.sequences[si].real) needs[si] = {add_job(p, synth_job(p, p.sequences[si], cache), o.timeout_seconds)};
  for (std::size_t si = 0; si < p.sequences.size(); ++si) {
    for (const auto& config : o.configs)
      add_job(p, run_job(p, o, p.sequences[si], configuration_by_name(config), needs[si]), o.timeout_seconds);
    if (p.peer) add_job(p, peer_job(p, o.peer_template, p.sequences[si], needs[si]), o.timeout_seconds);
  }
  return p;
}

std::vector<std::size_t> jobs_of_stage(const BenchPlan& plan, int stage) {
  std::vector<std::size_t> out;
  for (const auto& j : plan.jobs)
    if (j.stage == stage) out.push_back(j.number);
  return out;
}

int stage_count(const BenchPlan& plan) {
  int n = 0;
  for (const auto& j : plan.jobs) n = std::max(n, j.stage + 1);
  return n;
}

}  // namespace varslam::report
