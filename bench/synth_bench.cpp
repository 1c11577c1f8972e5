// Generator throughput: frames per second of `synth::generate` at 640x480 (render + sensor + PNG writing).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "synth/synth.hpp"

namespace {

void BM_Generate(benchmark::State& state, const char* scenario) {
  const auto dir = std::filesystem::temp_directory_path() / "varslam_synth_bench";
  varslam::synth::SynthConfig cfg;
  cfg.scenario = scenario;
  cfg.seconds = static_cast<double>(state.range(0));
  cfg.preview = false;
  std::size_t frames = 0;
  for (auto _ : state) {
    std::filesystem::remove_all(dir);
    frames += varslam::synth::generate(cfg, dir).frames;
  }
  std::filesystem::remove_all(dir);
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK_CAPTURE(BM_Generate, static, "static")->Arg(3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Generate, walking, "walking")->Arg(3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Generate, mixed, "mixed")->Arg(3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Generate, walking_30s, "walking")->Arg(30)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
