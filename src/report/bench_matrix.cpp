#include "report/bench_matrix.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "io/trajectory_io.hpp"
#include "report/bench_plan.hpp"
#include "synth/synth.hpp"

namespace varslam::report {
namespace fs = std::filesystem;

const std::vector<BenchConfiguration>& known_configurations() {
  static const std::vector<BenchConfiguration> configs = {
      {"huber", "ORB-SLAM3 baseline: Huber kernels, no detector", false, false},
      {"semantic", "VAR-SLAM-S: Huber kernels + depth-aware person filter", true, false},
      {"kernel", "VAR-SLAM-RK: Barron kernels (fixed shape in tracking, adaptive in mapping), no detector", false, true},
      {"full", "VAR-SLAM: Barron kernels + person filter", true, true}};
  return configs;
}

const BenchConfiguration& configuration_by_name(const std::string& name) {
  for (const auto& c : known_configurations())
    if (c.name == name) return c;
  throw InputError(fmt::format("bench: unknown configuration '{}' (known: huber, semantic, kernel, full)", name));
}

std::vector<std::string> configuration_overrides(const BenchConfiguration& config, const std::string& detector,
                                                 const fs::path& boxes_file) {
  std::vector<std::string> o;
  if (config.robust) {
    o = {"tracking.kernel=barron-fixed", "mapping.kernel=barron-adaptive"};  // tracking alpha: the default
  } else {
    o = {"tracking.kernel=huber", "mapping.kernel=huber"};
  }
  if (!config.semantic) {
    o.emplace_back("semantic.detector=none");
  } else if (detector == "boxes") {
    if (boxes_file.empty()) throw InputError("bench: configuration '" + config.name + "' needs a boxes file");
    o.emplace_back("semantic.detector=boxes");
    o.emplace_back("semantic.boxes_file=" + boxes_file.string());
  } else if (detector == "yolo") {
    o.emplace_back("semantic.detector=yolo");
  } else {
    throw InputError("bench: detector must be boxes or yolo, got '" + detector + "'");
  }
  return o;
}

const std::vector<NamedMatrix>& named_matrices() {
  static const std::vector<NamedMatrix> matrices = [] {
    const BenchOptions defaults;
    NamedMatrix quick{"default", "every scenario, 3-s sequences, 2 seeds", defaults.scenarios, defaults.paths,
                      defaults.configs, defaults.seeds, defaults.seconds};
    NamedMatrix large{"large_movers",
                      "a large box carried 0.6-1.5 m in front of the camera, alone and with two people, 20-s "
                      "sequences, 5 seeds",
                      {"large_box", "large_box_people"},
                      defaults.paths,
                      {"huber", "full"},
                      {1, 2, 3, 4, 5},
                      20.0};
    return std::vector<NamedMatrix>{quick, large};
  }();
  return matrices;
}

const NamedMatrix& matrix_by_name(const std::string& name) {
  std::vector<std::string> names;
  for (const auto& m : named_matrices()) {
    if (m.name == name) return m;
    names.push_back(m.name);
  }
  throw InputError(fmt::format("bench: unknown matrix '{}' (known: {})", name, fmt::join(names, ", ")));
}

std::string short_path_name(const std::string& folder_name) {
  std::string s = folder_name;
  const auto replace_prefix = [&s](const std::string& prefix, const std::string& with) {
    if (s.rfind(prefix, 0) == 0) s = with + s.substr(prefix.size());
  };
  replace_prefix("rgbd_dataset_freiburg", "fr");
  replace_prefix("rgbd_bonn_", "bonn_");
  return s;
}

CameraPathChoice resolve_camera_path(const std::string& entry, const fs::path& trajectories_dir, double seconds) {
  std::string spec = entry;
  std::optional<double> start;
  if (const auto at = spec.rfind('@'); at != std::string::npos) {
    try {
      std::size_t used = 0;
      start = std::stod(spec.substr(at + 1), &used);
      if (used != spec.size() - at - 1) throw std::invalid_argument("trailing characters");
    } catch (const std::exception&) {
      throw InputError(fmt::format("bench: path '{}': the start after '@' must be a number of seconds", entry));
    }
    spec = spec.substr(0, at);
  }
  fs::path p(spec);
  if (!fs::exists(p) && !trajectories_dir.empty() && fs::exists(trajectories_dir / spec)) p = trajectories_dir / spec;
  if (fs::is_directory(p)) p /= "groundtruth.txt";
  if (!fs::exists(p))
    throw InputError(fmt::format("bench: camera path '{}' not found (neither a file nor a folder under {})", entry,
                                 trajectories_dir.string()));
  const Trajectory traj = read_tum_trajectory(p);
  if (traj.size() < 2) throw InputError(fmt::format("{}: camera path needs at least two poses", p.string()));

  CameraPathChoice c;
  c.file = p;
  const std::string folder = p.filename() == "groundtruth.txt" ? p.parent_path().filename().string() : p.stem().string();
  c.name = short_path_name(folder);
  c.duration = traj.back().timestamp - traj.front().timestamp;
  // Half a second of margin: synth interpolates between recorded poses and needs one after the last frame.
  const double margin = 0.5;
  if (c.duration < seconds + margin)
    throw InputError(fmt::format("{}: camera path is {:.1f} s long, the benchmark needs {:.1f} s (+{:.1f} s margin)",
                                 p.string(), c.duration, seconds, margin));
  c.start = start ? *start : std::floor((c.duration - seconds) / 2.0 * 10.0) / 10.0;
  if (c.start < 0 || c.start + seconds + margin > c.duration)
    throw InputError(fmt::format("{}: a {:.1f} s window starting at {:.1f} s does not fit in the {:.1f} s path",
                                 p.string(), seconds, c.start, c.duration));
  return c;
}

std::vector<SequenceSpec> synthetic_sequences(const std::vector<std::string>& scenarios,
                                              const std::vector<CameraPathChoice>& paths,
                                              const std::vector<std::uint64_t>& seeds, double seconds,
                                              const fs::path& cache_dir, const std::string& sensor) {
  std::vector<SequenceSpec> out;
  for (const auto& scenario : scenarios) {
    for (const auto& path : paths) {
      for (const auto seed : seeds) {
        SequenceSpec s;
        s.scenario = scenario;
        s.path_name = path.name;
        s.path_file = path.file;
        s.path_start = path.start;
        s.seed = seed;
        s.seconds = seconds;
        s.sensor = sensor;
        s.id = fmt::format("{}__{}__s{}__{}s", scenario, path.name, seed, seconds);
        s.id += fmt::format("__at{}", path.start);
        if (sensor != "default") s.id += "__" + sensor;
        s.dir = cache_dir / s.id;
        out.push_back(std::move(s));
      }
    }
  }
  return out;
}

SequenceSpec real_sequence(const fs::path& folder) {
  if (!fs::is_directory(folder)) throw InputError(fmt::format("bench: --real {}: not a folder", folder.string()));
  SequenceSpec s;
  s.real = true;
  s.scenario = "real";
  s.dir = fs::absolute(folder).lexically_normal();
  if (s.dir.filename().empty()) s.dir = s.dir.parent_path();
  s.path_name = s.dir.filename().string();
  s.id = "real__" + s.path_name;
  return s;
}

std::vector<std::string> synth_arguments(const SequenceSpec& seq) {
  std::vector<std::string> a{"synth",       "--scenario", seq.scenario, "--seconds", fmt::format("{}", seq.seconds),
                             "--seed",      std::to_string(seq.seed), "--path", seq.path_file.string(),
                             "--path-start", fmt::format("{}", seq.path_start), "--out", seq.dir.string()};
  if (seq.sensor != "default") a.insert(a.end(), {"--sensor", seq.sensor});
  return a;
}

std::string synth_cache_key(const SequenceSpec& seq) {
  std::ostringstream k;
  k << "scenario=" << seq.scenario << "\npath=" << fs::absolute(seq.path_file).lexically_normal().string()
    << "\npath_start=" << fmt::format("{}", seq.path_start) << "\nseed=" << seq.seed
    << "\nseconds=" << fmt::format("{}", seq.seconds) << "\n";
  if (seq.sensor != "default") k << "sensor=" << seq.sensor << "\n";  // keeps the default sensor's caches valid
  // Cached sequences of an older generator are regenerated (synth::kGeneratorVersion).
  k << "generator=" << synth::kGeneratorVersion << "\n";
  return k.str();
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, ',')) {
    const auto b = item.find_first_not_of(" \t");
    const auto e = item.find_last_not_of(" \t");
    if (b != std::string::npos) out.push_back(item.substr(b, e - b + 1));
  }
  return out;
}

}  // namespace varslam::report
