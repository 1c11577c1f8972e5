#include "report/bench_plan_file.hpp"

#include <fmt/format.h>

#include <sstream>

#include "core/error.hpp"
#include "report/bench_files.hpp"
#include "report/bench_job.hpp"

namespace varslam::report {
namespace fs = std::filesystem;
namespace {

// Where a key is read from, for error messages: "<file> line 3".
struct Where {
  const fs::path& file;
  std::size_t line;
  std::string str() const { return fmt::format("{} line {}", file.string(), line); }
};

const nlohmann::json& key(const nlohmann::json& j, const char* name, nlohmann::json::value_t type, const Where& w) {
  if (!j.contains(name)) throw InputError(fmt::format("{}: key '{}' is missing", w.str(), name));
  const nlohmann::json& v = j.at(name);
  const bool number_ok = type == nlohmann::json::value_t::number_float && v.is_number();
  const bool unsigned_ok = type == nlohmann::json::value_t::number_unsigned && v.is_number_unsigned();
  if (v.type() != type && !number_ok && !unsigned_ok)
    throw InputError(fmt::format("{}: key '{}' has the wrong type ({})", w.str(), name, v.type_name()));
  return v;
}

std::string key_string(const nlohmann::json& j, const char* name, const Where& w) {
  return key(j, name, nlohmann::json::value_t::string, w).get<std::string>();
}
double key_number(const nlohmann::json& j, const char* name, const Where& w) {
  return key(j, name, nlohmann::json::value_t::number_float, w).get<double>();
}
std::size_t key_count(const nlohmann::json& j, const char* name, const Where& w) {
  return key(j, name, nlohmann::json::value_t::number_unsigned, w).get<std::size_t>();
}
bool key_bool(const nlohmann::json& j, const char* name, const Where& w) {
  return key(j, name, nlohmann::json::value_t::boolean, w).get<bool>();
}
std::vector<std::string> key_strings(const nlohmann::json& j, const char* name, const Where& w) {
  const auto& a = key(j, name, nlohmann::json::value_t::array, w);
  std::vector<std::string> out;
  for (const auto& v : a) {
    if (!v.is_string()) throw InputError(fmt::format("{}: key '{}' must hold strings", w.str(), name));
    out.push_back(v.get<std::string>());
  }
  return out;
}

PlanJob::Kind kind_from_name(const std::string& name, const Where& w) {
  for (const auto k : {PlanJob::Kind::Synth, PlanJob::Kind::Run, PlanJob::Kind::Peer})
    if (kind_name(k) == name) return k;
  throw InputError(fmt::format("{}: key 'kind' is '{}', expected synth, run or peer", w.str(), name));
}

SequenceSpec sequence_from_json(const nlohmann::json& j, const Where& w) {
  SequenceSpec s;
  s.id = key_string(j, "id", w);
  s.scenario = key_string(j, "scenario", w);
  s.path_name = key_string(j, "path", w);
  s.dir = key_string(j, "dir", w);
  s.real = key_bool(j, "real", w);
  if (!s.real) {
    s.path_file = key_string(j, "path_file", w);
    s.path_start = key_number(j, "path_start_s", w);
    s.seed = key_count(j, "seed", w);
    s.seconds = key_number(j, "seconds", w);
    if (j.contains("sensor")) s.sensor = key_string(j, "sensor", w);  // absent: written before sensors had names
  }
  return s;
}

PlanJob job_from_json(const nlohmann::json& j, const Where& w) {
  PlanJob job;
  job.number = key_count(j, "job", w);
  job.kind = kind_from_name(key_string(j, "kind", w), w);
  job.sequence = key_string(j, "sequence", w);
  job.config = key_string(j, "config", w);
  job.detector = key_string(j, "detector", w);
  job.argv = key_strings(j, "argv", w);
  if (job.argv.empty()) throw InputError(fmt::format("{}: key 'argv' is empty", w.str()));
  job.command = key_string(j, "command", w);
  job.out_dir = key_string(j, "out", w);
  job.log_file = key_string(j, "log", w);
  for (const auto& n : key(j, "needs", nlohmann::json::value_t::array, w)) {
    if (!n.is_number_unsigned()) throw InputError(fmt::format("{}: key 'needs' must hold job numbers", w.str()));
    job.needs.push_back(n.get<std::size_t>());
  }
  job.stage = static_cast<int>(key_count(j, "stage", w));
  job.timeout_seconds = key_number(j, "timeout_s", w);
  job.time_limit_seconds = key_number(j, "time_limit_s", w);
  job.memory_mb = static_cast<int>(key_count(j, "memory_mb", w));
  return job;
}

// The plan file keeps its keys in this order (format and version first), for people reading it.
nlohmann::ordered_json ordered(const nlohmann::json& j) { return nlohmann::ordered_json::parse(j.dump()); }

nlohmann::ordered_json header_json(const BenchPlan& p) {
  nlohmann::ordered_json seqs = nlohmann::ordered_json::array();
  for (const auto& s : p.sequences) seqs.push_back(ordered(to_json(s)));
  return {{"format", kBenchPlanFormat},
          {"version", kBenchPlanVersion},
          {"id", p.id},
          {"created_utc", p.created_utc},
          {"dir", p.dir.string()},
          {"executable", p.executable.string()},
          {"git_describe", p.git_describe},
          {"command_line", p.command_line},
          {"machine", ordered(p.machine)},
          {"options", ordered(p.options)},
          {"configs", p.configs},
          {"peer", p.peer},
          {"peer_name", p.peer_name},
          {"peer_trajectory", p.peer_trajectory},
          {"jobs", p.jobs.size()},
          {"sequences", seqs}};
}

// Fills the plan from its header line; returns the number of jobs the header announces.
std::size_t read_header(BenchPlan& p, const nlohmann::json& h, const Where& w) {
  if (!h.is_object() || !h.contains("format") || h["format"] != kBenchPlanFormat)
    throw InputError(fmt::format("{}: not a varslam bench plan (its first line needs \"format\": \"{}\")", w.str(),
                                 kBenchPlanFormat));
  const nlohmann::json& version = key(h, "version", nlohmann::json::value_t::number_unsigned, w);
  if (version.get<std::size_t>() != static_cast<std::size_t>(kBenchPlanVersion))
    throw InputError(fmt::format("{}: key 'version' is {}, this varslam reads plan version {}; plan it again with "
                                 "this varslam (varslam bench plan)",
                                 w.str(), version.dump(), kBenchPlanVersion));
  p.id = key_string(h, "id", w);
  p.created_utc = key_string(h, "created_utc", w);
  p.executable = key_string(h, "executable", w);
  p.git_describe = key_string(h, "git_describe", w);
  p.command_line = key_string(h, "command_line", w);
  p.machine = key(h, "machine", nlohmann::json::value_t::object, w);
  p.options = key(h, "options", nlohmann::json::value_t::object, w);
  p.configs = key_strings(h, "configs", w);
  p.peer = key_bool(h, "peer", w);
  p.peer_name = key_string(h, "peer_name", w);
  p.peer_trajectory = key_string(h, "peer_trajectory", w);
  for (const auto& s : key(h, "sequences", nlohmann::json::value_t::array, w)) p.sequences.push_back(sequence_from_json(s, w));
  return key_count(h, "jobs", w);
}
}  // namespace

std::unique_ptr<OutputFolder> claim_bench_folder(const fs::path& out) {
  // The plan and the summary files are the benchmark's own; each run folder is its run's (varslam run keeps its
  // manifest).
  return std::make_unique<OutputFolder>(fs::absolute(out).lexically_normal(),
                                        std::vector<OutputFile>{{kBenchPlanFile, "benchmark plan"},
                                                                {"results.json", "benchmark results"},
                                                                {"table.md", "benchmark table"},
                                                                {"index.html", "benchmark summary"}});
}

void write_bench_plan(const BenchPlan& p, bool fresh_sequences) {
  for (const auto& job : p.jobs) {
    if (job.kind == PlanJob::Kind::Synth) {
      if (fresh_sequences) forget_cached_sequence(job);
      fs::create_directories(job.log_file.parent_path());
      continue;
    }
    fs::create_directories(job.out_dir);
    // A stale metrics.json (or trajectory) from an earlier benchmark must not pass for this plan's result.
    clear_job_outputs(p, job);
  }
  std::string text = header_json(p).dump() + "\n";
  for (const auto& job : p.jobs) text += job_line(job).dump() + "\n";
  write_text_file(p.file(), text);
}

BenchPlan read_bench_plan(const fs::path& dir) {
  if (!fs::is_directory(dir))
    throw InputError(fmt::format("{}: no such folder (give the --out folder of varslam bench plan)", dir.string()));
  BenchPlan p;
  p.dir = fs::absolute(dir).lexically_normal();
  const fs::path file = p.file();
  if (!fs::exists(file))
    throw InputError(fmt::format("{}: not found; write a plan with varslam bench plan --out {}", file.string(),
                                 dir.string()));
  std::istringstream in(read_text_file(file));
  std::string line;
  std::size_t line_no = 0, announced = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    const Where w{file, line_no};
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception& e) {
      throw InputError(fmt::format("{}: not JSON ({})", w.str(), e.what()));
    }
    if (line_no == 1) {
      announced = read_header(p, j, w);
      continue;
    }
    if (!j.is_object()) throw InputError(fmt::format("{}: a job line must be a JSON object", w.str()));
    PlanJob job = job_from_json(j, w);
    if (job.number != p.jobs.size())
      throw InputError(fmt::format("{}: key 'job' is {}, expected {} (jobs are numbered in order)", w.str(),
                                   job.number, p.jobs.size()));
    for (const auto n : job.needs)
      if (n >= job.number)
        throw InputError(fmt::format("{}: key 'needs' names job {}, which is not an earlier job", w.str(), n));
    (void)p.sequence(job.sequence);
    p.jobs.push_back(std::move(job));
  }
  if (line_no == 0) throw InputError(fmt::format("{}: empty, not a varslam bench plan", file.string()));
  if (p.jobs.size() != announced)
    throw InputError(fmt::format("{}: key 'jobs' of the header announces {} jobs, the file has {} (cut short?)",
                                 file.string(), announced, p.jobs.size()));
  return p;
}

nlohmann::json to_json(const PlanJob& j) { return nlohmann::json::parse(job_line(j).dump()); }

nlohmann::ordered_json job_line(const PlanJob& j) {
  return {{"job", j.number},
          {"kind", kind_name(j.kind)},
          {"sequence", j.sequence},
          {"config", j.config},
          {"detector", j.detector},
          {"stage", j.stage},
          {"needs", j.needs},
          {"out", j.out_dir.string()},
          {"log", j.log_file.string()},
          {"timeout_s", j.timeout_seconds},
          {"time_limit_s", j.time_limit_seconds},
          {"memory_mb", j.memory_mb},
          {"command", j.command},
          {"argv", j.argv}};
}

nlohmann::json to_json(const SequenceSpec& s) {
  nlohmann::json j = {{"id", s.id}, {"scenario", s.scenario}, {"path", s.path_name}, {"dir", s.dir.string()},
                      {"real", s.real}};
  if (!s.real)
    j.update({{"path_file", s.path_file.string()}, {"path_start_s", s.path_start}, {"seed", s.seed},
              {"seconds", s.seconds}, {"sensor", s.sensor}});
  return j;
}
}  // namespace varslam::report
