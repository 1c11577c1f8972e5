// How long track() waits while another thread saves the map (Slam::save_map in real-time mode): the real kitchen's
// first 300 frames fed as fast as tracking takes them, a map saved every `range(0)` frames from a second thread
// (0: never, the reference). Counters: track() latency median / p95 / max over the frames tracked while a save ran
// (all frames for the reference), and the save's own duration.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <thread>
#include <varslam/varslam.hpp>

#include "io/dataset.hpp"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Kitchen {
  varslam::Config config;
  std::vector<varslam::RgbdFrame> frames;
};

const Kitchen* kitchen() {
  static const Kitchen* k = []() -> Kitchen* {
    const fs::path dir = fs::path(VARSLAM_SHARED_DIR) / "realdata" / "7scenes_redkitchen";
    if (!fs::exists(dir / "rgb.txt")) return nullptr;
    auto* out = new Kitchen;
    out->config = varslam::Config::from_file((dir / "settings.yaml").string());
    out->config.set("semantic.detector", "none");
    // The colour camera the kitchen's folder run estimates: a session fed images has no frames to estimate it from.
    out->config.set("depth.registration", "off");
    const auto ds = varslam::open_dataset(dir, varslam::settings_for_dataset(dir, std::nullopt));
    for (std::size_t i = 0; i < std::min<std::size_t>(300, ds->size()); ++i) out->frames.push_back(ds->load(i));
    return out;
  }();
  return k;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

void BM_TrackWhileSavingTheMap(benchmark::State& state) {
  const Kitchen* k = kitchen();
  if (!k) {
    state.SkipWithError("no ../shared/realdata/7scenes_redkitchen");
    return;
  }
  const int every = static_cast<int>(state.range(0));
  const fs::path file = fs::temp_directory_path() / ("varslam_save_bench_" + std::to_string(::getpid()) + ".map");
  std::vector<double> during, save_ms;
  for (auto _ : state) {
    varslam::Slam slam(k->config, varslam::Mode::RealTime);
    std::atomic<int> save_requests{0};
    std::atomic<bool> saving{false}, done{false};
    std::thread saver([&] {
      int served = 0;
      while (!done) {
        if (save_requests.load() == served) {
          std::this_thread::sleep_for(std::chrono::microseconds(200));
          continue;
        }
        saving = true;
        const auto t0 = Clock::now();
        slam.save_map(file.string());
        save_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        saving = false;
        ++served;
      }
    });
    for (std::size_t i = 0; i < k->frames.size(); ++i) {
      const auto& f = k->frames[i];
      if (every > 0 && i > 30 && i % static_cast<std::size_t>(every) == 0) ++save_requests;
      const bool overlapped = saving.load();
      const auto t0 = Clock::now();
      slam.track(f.bgr, f.depth, f.timestamp);
      const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
      if (every == 0 || overlapped || saving.load()) during.push_back(ms);
    }
    done = true;
    saver.join();
    slam.finish();
  }
  fs::remove(file);
  state.counters["track_median_ms"] = percentile(during, 0.5);
  state.counters["track_p95_ms"] = percentile(during, 0.95);
  state.counters["track_max_ms"] = percentile(during, 1.0);
  state.counters["frames_counted"] = static_cast<double>(during.size());
  state.counters["save_median_ms"] = percentile(save_ms, 0.5);
}

BENCHMARK(BM_TrackWhileSavingTheMap)->Arg(0)->Arg(10)->Iterations(1)->Repetitions(3)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
