// `varslam dense-bench`: the dense map against the generator's static geometry and movers (report/dense_bench.hpp),
// each scenario with the mover exclusion on and off.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "commands.hpp"
#include "dense/dense_mapper.hpp"
#include "eval/ate.hpp"
#include "io/atomic_file.hpp"
#include "io/dataset.hpp"
#include "io/settings_registry.hpp"
#include "io/trajectory_io.hpp"
#include "pipeline/slam.hpp"
#include "report/dense_bench.hpp"
#include "synth/world.hpp"

namespace varslam::cli {

namespace {

struct Run {
  report::DenseScores scores;
  dense::DenseStats stats;
  double seconds = 0;
  std::size_t keyframes = 0;
};

Run run_one(const std::filesystem::path& seq, const synth::World& world, const std::vector<std::string>& overrides,
            const std::filesystem::path& mesh_out) {
  Settings settings = settings_for_dataset(seq, std::nullopt);
  apply_setting_overrides(settings, overrides);
  const auto ds = open_dataset(seq, settings);
  const auto t0 = std::chrono::steady_clock::now();
  Pipeline slam(settings);
  slam.calibrate_depth({});
  for (std::size_t i = 0; i < ds->size(); ++i) slam.track(ds->load(i));
  slam.finish();
  Run r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  dense::DenseMapper& d = *slam.dense_map();
  const dense::Mesh mesh = d.mesh();
  const std::vector<dense::OccupancyVoxel> occ = d.occupancy();
  dense::write_mesh_ply(mesh, mesh_out);
  report::DenseTruthOptions opt;
  opt.voxel_size = d.config().tsdf.voxel_size;
  opt.max_range = d.config().tsdf.max_range;
  r.scores = report::score_dense_map(world, settings.camera, mesh, occ, opt);
  r.stats = d.stats();
  r.keyframes = slam.summary().keyframes;
  return r;
}

}  // namespace

void add_dense_bench_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("dense-bench",
                                 "Dense map on synthetic scenarios: accuracy, completeness and ghosts, movers left out "
                                 "and not (BENCHMARKS.md)");
  struct Options {
    std::vector<std::string> scenarios{"static", "walking", "mixed", "unknown_box", "large_box", "large_box_people"};
    double seconds = 10;
    std::uint64_t seed = 1;
    std::string out = "out/dense_bench";
    std::vector<std::string> overrides;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("--scenarios", o->scenarios, "Scenarios (comma separated)")->delimiter(',')->capture_default_str();
  cmd->add_option("--seconds", o->seconds, "Sequence length")->capture_default_str()->check(finite_range(0.5, 600.0));
  cmd->add_option("--seed", o->seed, "Generator seed")->capture_default_str();
  cmd->add_option("--out", o->out, "Folder for sequences, meshes and dense_bench.json")->capture_default_str();
  cmd->add_option("--set", o->overrides, "Override a setting for every run: section.key=value (repeatable)");
  cmd->callback([o] {
    namespace fs = std::filesystem;
    const fs::path out = o->out;
    fs::create_directories(out);
    nlohmann::json all = nlohmann::json::array();
    std::printf("%-17s %-8s %5s %9s %9s %8s %8s %9s %8s %8s %8s\n", "scenario", "movers", "kf", "acc_mean", "acc_med",
                "acc<2cm", "comp<2cm", "comp_med", "ghost%", "ghostvtx", "fuse_ms");
    for (const std::string& sc : o->scenarios) {
      synth::SynthConfig cfg;
      cfg.scenario = sc;
      cfg.seconds = o->seconds;
      cfg.seed = o->seed;
      cfg.preview = false;
      const fs::path seq = out / fmt::format("seq_{}_{}s_seed{}_g{}", sc, o->seconds, o->seed, synth::kGeneratorVersion);
      if (!fs::exists(seq / "groundtruth.txt")) synth::generate(cfg, seq);
      const synth::World world = synth::build_world(cfg);
      for (const bool exclude : {true, false}) {
        std::vector<std::string> ov = {"dense.enabled=true", "semantic.detector=boxes", "depth.registration=off",
                                       fmt::format("dense.exclude_movers={}", exclude ? "true" : "false")};
        ov.insert(ov.end(), o->overrides.begin(), o->overrides.end());
        const std::string tag = exclude ? "excluded" : "fused";
        const Run r = run_one(seq, world, ov, out / fmt::format("{}_{}.ply", sc, tag));
        std::vector<double> ms = r.stats.integrate_ms;
        std::sort(ms.begin(), ms.end());
        const double med = ms.empty() ? 0 : ms[ms.size() / 2];
        const report::DenseScores& s = r.scores;
        std::printf("%-17s %-8s %5zu %9.2f %9.2f %8.3f %8.3f %9.2f %8.3f %8zu %8.1f\n", sc.c_str(), tag.c_str(),
                    r.keyframes, s.accuracy_mean_cm, s.accuracy_median_cm, s.accuracy_within, s.completeness_within,
                    s.completeness_median_cm, 100.0 * s.ghost_share, s.ghost_vertices, med);
        std::fflush(stdout);
        nlohmann::json j = s.to_json();
        j["scenario"] = sc;
        j["movers"] = tag;
        j["keyframes"] = r.keyframes;
        j["fuse_ms_median"] = med;
        j["final_rebuild_ms"] = r.stats.final_rebuild_ms;
        j["moving_pixel_share"] = r.stats.moving_pixel_share;
        j["run_seconds"] = r.seconds;
        all.push_back(j);
      }
    }
    const nlohmann::json doc = {{"seconds", o->seconds}, {"seed", o->seed}, {"overrides", o->overrides}, {"runs", all}};
    write_file_atomically(out / "dense_bench.json", doc.dump(2) + "\n", "benchmark results");
    std::printf("results: %s\n", (out / "dense_bench.json").c_str());
  });
}

}  // namespace varslam::cli
