// Soak: the same sequence run again and again in one process through the
// pipeline API (varslam::Pipeline), as an embedding application would. Per run:
// peak and final resident memory, per-frame tracking time (median of the first
// and last thirds, to see growth), ATE of the final and live trajectories, and
// a hash of the final trajectory (deterministic mode: every run must give the
// same one).
//   varslam_soak DATASET [--runs N] [--set section.key=value ...] [--json FILE]
// Build with AddressSanitizer to check that repeated runs leak nothing (the
// leak checker runs at exit).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "eval/ate.hpp"
#include "io/dataset.hpp"
#include "io/settings_registry.hpp"
#include "io/trajectory_io.hpp"
#include "pipeline/slam.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// A /proc/self/status field in MiB ("VmHWM", "VmRSS"); -1 where the kernel does
// not give it.
double status_mib(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1)) / 1024.0;
  return -1;
}

// Starts a new peak for VmHWM (Linux: writing 5 to clear_refs resets the
// high-water mark).
void reset_peak_rss() { std::ofstream("/proc/self/clear_refs") << "5"; }

// FNV-1a over the trajectory's printed form: equal text, equal hash.
std::string trajectory_hash(const varslam::Trajectory& t) {
  std::uint64_t h = 1469598103934665603ull;
  for (const auto& p : t) {
    const auto& x = p.T_wc.matrix();
    const std::string s = fmt::format("{:.6f} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g}", p.timestamp, x(0, 3), x(1, 3),
                                      x(2, 3), x(0, 0), x(1, 1), x(2, 2));
    for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  }
  return fmt::format("{:016x}", h);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

nlohmann::json one_run(const varslam::Dataset& dataset, const varslam::Settings& settings,
                       const std::optional<varslam::Trajectory>& gt) {
  using namespace varslam;
  reset_peak_rss();
  const auto t0 = Clock::now();
  Pipeline slam(settings);
  std::vector<RgbdFrame> samples;  // as the CLI does: 10 frames spread over the first 300
  if (slam.wants_depth_samples())
    for (std::size_t k = 0; k < 10; ++k)
      samples.push_back(dataset.load(k * std::min<std::size_t>(dataset.size(), 300) / 10));
  slam.calibrate_depth(samples);
  FramePrefetcher prefetch(dataset, 4, 0, dataset.size(), slam.frame_preparation());
  std::vector<double> track_ms;
  std::size_t tracked = 0;
  while (auto frame = prefetch.next()) {
    const auto t = Clock::now();
    const FrameResult r = slam.track(*frame);
    track_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t).count());
    tracked += r.T_wc.has_value();
  }
  slam.finish();
  const Trajectory final_traj = slam.camera_trajectory();
  const std::size_t third = track_ms.size() / 3;
  nlohmann::json j = {
      {"frames", track_ms.size()},
      {"tracked", tracked},
      {"keyframes", slam.summary().keyframes},
      {"map_points", slam.summary().map_points},
      {"wall_s", std::chrono::duration<double>(Clock::now() - t0).count()},
      {"track_median_ms", median(track_ms)},
      {"track_median_first_third_ms", median({track_ms.begin(), track_ms.begin() + third})},
      {"track_median_last_third_ms", median({track_ms.end() - third, track_ms.end()})},
      {"peak_rss_mib", status_mib("VmHWM")},
      {"trajectory_hash", trajectory_hash(final_traj)},
  };
  if (gt && final_traj.size() >= 2) {
    const AteResult fin = evaluate_ate(*gt, final_traj), live = evaluate_ate(*gt, slam.live_trajectory());
    j["ate_final_cm"] = 100 * fin.stats.rmse;
    j["ate_final_max_cm"] = 100 * fin.stats.max;
    j["ate_live_cm"] = 100 * live.stats.rmse;
    j["ate_live_max_cm"] = 100 * live.stats.max;
  }
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Runs one sequence repeatedly in one process through the "
      "pipeline API and reports memory and time"};
  std::string dataset_dir, json_file;
  int runs = 10;
  std::vector<std::string> overrides;
  app.add_option("dataset", dataset_dir, "dataset folder")->required();
  app.add_option("--runs", runs, "how many runs")->check(CLI::PositiveNumber);
  app.add_option("--set", overrides, "setting override section.key=value");
  app.add_option("--json", json_file, "write the per-run figures here");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::warn);
  try {
    using namespace varslam;
    Settings settings = settings_for_dataset(dataset_dir, std::nullopt);
    apply_setting_overrides(settings, overrides);
    const auto dataset = open_dataset(dataset_dir, settings);
    std::optional<Trajectory> gt;
    if (dataset->groundtruth()) gt = read_tum_trajectory(*dataset->groundtruth());
    nlohmann::json all = nlohmann::json::array();
    fmt::print(
        "run  frames tracked  wall_s  track_ms(med first/last third)  "
        "peak_MiB rss_after_MiB  ATE final/max  "
        "live/max (cm)  hash\n");
    for (int k = 0; k < runs; ++k) {
      nlohmann::json j = one_run(*dataset, settings, gt);
      j["rss_after_mib"] = status_mib("VmRSS");
      fmt::print(
          "{:3d} {:7d} {:7d} {:7.1f}  {:6.2f} ({:6.2f} / {:6.2f})           "
          "{:8.0f} {:13.0f}  {:5.2f}/{:6.2f}  "
          "{:5.2f}/{:6.2f}  {}\n",
          k + 1, j["frames"].get<int>(), j["tracked"].get<int>(), j["wall_s"].get<double>(),
          j["track_median_ms"].get<double>(), j["track_median_first_third_ms"].get<double>(),
          j["track_median_last_third_ms"].get<double>(), j["peak_rss_mib"].get<double>(),
          j["rss_after_mib"].get<double>(), j.value("ate_final_cm", -1.0), j.value("ate_final_max_cm", -1.0),
          j.value("ate_live_cm", -1.0), j.value("ate_live_max_cm", -1.0), j["trajectory_hash"].get<std::string>());
      std::fflush(stdout);
      all.push_back(j);
    }
    if (!json_file.empty()) std::ofstream(json_file) << all.dump(2) << "\n";
  } catch (const varslam::InputError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 2;
  }
  return 0;
}
