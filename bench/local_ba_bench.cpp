// Cost of Local BA on fixed problems recorded from the real kitchen (issue #30): the same three windows (small,
// default, large) are solved by every commit, so a change in solver cost shows here and nowhere else.
//
//   build/bin/local_ba_bench [benchmark options]       time the recorded problems (bench/data/local_ba/*.lba)
//   build/bin/local_ba_bench --record [--frames N] [--out DIR] [SEQUENCE_DIR]
//                                                      run SEQUENCE_DIR (default: the kitchen) deterministically,
//                                                      keep the Local BA problems at the 10th percentile, median
//                                                      and maximum of the observation count
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "optim/ba_problem_io.hpp"
#include "optim/local_ba.hpp"
#include "slam/config.hpp"
#include "slam/system.hpp"

namespace {

namespace fs = std::filesystem;
using namespace varslam;

const fs::path kDataDir = fs::path(VARSLAM_BENCH_DATA_DIR) / "local_ba";
const char* const kWindows[] = {"small", "default", "large"};

struct RecordOptions {
  std::size_t frames = 1000;
  fs::path out = kDataDir;
  fs::path sequence = fs::path(VARSLAM_SHARED_DIR) / "realdata/7scenes_redkitchen";
};

int free_keyframes(const optim::BaProblem& p) {
  return static_cast<int>(std::count_if(p.keyframes.begin(), p.keyframes.end(), [](const auto& k) { return !k.fixed; }));
}

int record(const RecordOptions& o) {
  const Settings settings = settings_for_dataset(o.sequence, std::nullopt);
  slam::SlamConfig cfg = slam::slam_config_from(settings);
  std::vector<optim::RecordedBaProblem> recorded;
  cfg.mapping.ba_observer = [&](const PinholeCamera& cam, const optim::BaProblem& p, const optim::BaConfig& bc) {
    optim::RecordedBaProblem r{cam, p, bc};
    r.config.observer = nullptr;
    recorded.push_back(std::move(r));
  };
  const auto dataset = open_dataset(o.sequence, settings);
  slam::System system(cfg, settings.camera, settings.close_depth_m(), slam::RunMode::Deterministic, nullptr);
  const std::size_t n = std::min(o.frames, dataset->size());
  for (std::size_t i = 0; i < n; ++i) {
    system.process(dataset->load(i));
    if (i % 100 == 0) fmt::print(stderr, "\rrecording: frame {}/{}, {} Local BA problems", i, n, recorded.size());
  }
  system.finish();
  fmt::print(stderr, "\n");
  if (recorded.empty()) {
    fmt::print(stderr, "local_ba_bench: {} made no Local BA problem in {} frames\n", o.sequence.string(), n);
    return 1;
  }
  std::vector<std::size_t> order(recorded.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return recorded[a].problem.observations.size() < recorded[b].problem.observations.size();
  });
  const std::size_t picks[] = {order[order.size() / 10], order[order.size() / 2], order.back()};
  fs::create_directories(o.out);
  for (int w = 0; w < 3; ++w) {
    const optim::RecordedBaProblem& r = recorded[picks[w]];
    const fs::path file = o.out / (std::string(kWindows[w]) + ".lba");
    optim::write_ba_problem(file, r);
    fmt::print("{}: problem {} of {}: {} free + {} fixed keyframes, {} points, {} observations -> {}\n", kWindows[w],
               picks[w], recorded.size(), free_keyframes(r.problem),
               r.problem.keyframes.size() - static_cast<std::size_t>(free_keyframes(r.problem)), r.problem.points.size(),
               r.problem.observations.size(), file.string());
  }
  return 0;
}

void solve_recorded(benchmark::State& state, const optim::RecordedBaProblem& r, optim::BaSolver solver) {
  optim::BaConfig config = r.config;
  config.solver = solver;
  optim::BaResult last;
  for (auto _ : state) {
    state.PauseTiming();
    optim::BaProblem problem = r.problem;  // solved in place: every iteration starts from the recorded state
    state.ResumeTiming();
    last = optim::solve_local_ba(r.camera, problem, config);
    benchmark::DoNotOptimize(problem.points.data());
  }
  state.counters["free_kfs"] = free_keyframes(r.problem);
  state.counters["kfs"] = static_cast<double>(r.problem.keyframes.size());
  state.counters["points"] = static_cast<double>(r.problem.points.size());
  state.counters["obs"] = static_cast<double>(r.problem.observations.size());
  state.counters["iterations"] = last.solver_iterations;
  state.counters["solves"] = last.solves;
  state.counters["cost_ratio"] = last.final_cost / std::max(last.initial_cost, 1e-12);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc > 1 && std::string(argv[1]) == "--record") {
      RecordOptions o;
      for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        if ((a == "--frames" || a == "--out") && i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
        if (a == "--frames") o.frames = std::stoul(argv[++i]);
        else if (a == "--out") o.out = argv[++i];
        else if (a.starts_with("--")) throw std::invalid_argument("unknown option " + a);
        else o.sequence = a;
      }
      return record(o);
    }
    std::vector<optim::RecordedBaProblem> problems;
    problems.reserve(std::size(kWindows));  // the benchmarks hold indices into it
    for (const char* w : kWindows) {
      const fs::path file = kDataDir / (std::string(w) + ".lba");
      problems.push_back(optim::read_ba_problem(file));
      for (const auto& [name, solver] : {std::pair{"schur", optim::BaSolver::Schur}, {"ceres", optim::BaSolver::Ceres}})
        benchmark::RegisterBenchmark(fmt::format("LocalBa/{}/{}", w, name).c_str(),
                                     [&problems, i = problems.size() - 1, solver = solver](benchmark::State& s) {
                                       solve_recorded(s, problems[i], solver);
                                     })
            ->Unit(benchmark::kMillisecond);
    }
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
  } catch (const std::exception& e) {
    fmt::print(stderr, "local_ba_bench: {}\n", e.what());
    return 1;
  }
  return 0;
}
