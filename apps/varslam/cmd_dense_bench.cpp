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
#include "eval/association.hpp"
#include "io/trajectory_io.hpp"
#include "core/error.hpp"
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

// A real sequence: the SLAM run's dense map against one fused from the same keyframes at their ground-truth poses.
nlohmann::json real_sequence(const std::filesystem::path& dir, const std::vector<std::string>& user_overrides,
                             std::size_t max_frames, const std::filesystem::path& out) {
  Settings settings = settings_for_dataset(dir, std::nullopt);
  std::vector<std::string> ov = {"dense.enabled=true"};
  ov.insert(ov.end(), user_overrides.begin(), user_overrides.end());
  apply_setting_overrides(settings, ov);
  const auto ds = open_dataset(dir, settings);
  if (!ds->groundtruth()) throw InputError(fmt::format("{}: no groundtruth.txt", dir.string()));
  const Trajectory gt = read_tum_trajectory(*ds->groundtruth());
  const std::size_t n = std::min(max_frames, ds->size());
  Pipeline slam(settings);
  std::vector<RgbdFrame> samples;
  if (slam.wants_depth_samples())
    for (std::size_t k = 0; k < 10; ++k) samples.push_back(ds->load(k * std::min<std::size_t>(n, 300) / 10));
  slam.calibrate_depth(samples);
  const auto prepare = slam.frame_preparation();
  struct Kept {
    double t;
    cv::Mat depth, bgr;
  };
  std::vector<Kept> keyframes;
  for (std::size_t i = 0; i < n; ++i) {
    RgbdFrame f = ds->load(i);
    prepare(f);
    if (slam.track(f).keyframe) keyframes.push_back({f.timestamp, f.depth, f.bgr});
  }
  slam.finish();
  dense::DenseMapper& d = *slam.dense_map();
  dense::Mesh mesh = d.mesh();
  const AteResult ate = evaluate_ate(gt, slam.camera_trajectory());
  for (auto& v : mesh.vertices) v = ate.alignment.apply(v.cast<double>()).cast<float>();

  dense::DenseConfig ref_cfg = d.config();
  ref_cfg.exclude_movers = false;
  dense::DenseMapper ref(ref_cfg, slam.settings().camera, false);
  std::vector<double> gt_stamps;
  for (const auto& p : gt) gt_stamps.push_back(p.timestamp);
  std::size_t used = 0;
  for (const Kept& k : keyframes) {
    const std::size_t j = nearest_timestamp_index(gt_stamps, k.t);
    if (j >= gt.size() || std::abs(gt[j].timestamp - k.t) > 0.02) continue;
    dense::DenseKeyframe kf;
    kf.depth = k.depth;
    kf.bgr = k.bgr;
    kf.pose = [T = gt[j].T_wc] { return T; };
    ref.add(std::move(kf));
    ++used;
  }
  ref.finish();
  const dense::Mesh ref_mesh = ref.mesh();
  dense::write_mesh_ply(mesh, out / "real_slam_aligned.ply");
  dense::write_mesh_ply(ref_mesh, out / "real_groundtruth_poses.ply");
  const report::MeshComparison c = report::compare_meshes(mesh.vertices, ref_mesh.vertices);
  std::vector<double> ms = d.stats().integrate_ms;
  std::sort(ms.begin(), ms.end());
  nlohmann::json j = c.to_json();
  j["dataset"] = dir.string();
  j["frames"] = n;
  j["keyframes"] = keyframes.size();
  j["keyframes_with_groundtruth"] = used;
  j["ate_rmse_cm"] = 100.0 * ate.stats.rmse;
  j["fuse_ms_median"] = ms.empty() ? 0.0 : ms[ms.size() / 2];
  j["final_rebuild_ms"] = d.stats().final_rebuild_ms;
  std::printf("real %s: %zu frames, %zu keyframes, ATE %.2f cm; mesh vs ground-truth-pose mesh: accuracy mean %.2f cm, "
              "median %.2f cm, %.1f %% within 2 cm; completeness %.1f %% within 2 cm; fuse %.1f ms/keyframe\n",
              dir.string().c_str(), n, keyframes.size(), 100.0 * ate.stats.rmse, c.accuracy_mean_cm,
              c.accuracy_median_cm, 100.0 * c.accuracy_within, 100.0 * c.completeness_within,
              j["fuse_ms_median"].get<double>());
  return j;
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
    std::string real;
    std::size_t max_frames = SIZE_MAX;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("--scenarios", o->scenarios, "Scenarios (comma separated)")->delimiter(',')->capture_default_str();
  cmd->add_option("--seconds", o->seconds, "Sequence length")->capture_default_str()->check(finite_range(0.5, 600.0));
  cmd->add_option("--seed", o->seed, "Generator seed")->capture_default_str();
  cmd->add_option("--out", o->out, "Folder for sequences, meshes and dense_bench.json")->capture_default_str();
  cmd->add_option("--real", o->real,
                  "A real sequence with ground truth instead (7-Scenes kitchen): the mesh against one fused from the "
                  "ground-truth poses of the same keyframes");
  cmd->add_option("--max-frames,-n", o->max_frames, "With --real: at most this many frames");
  cmd->add_option("--set", o->overrides, "Override a setting for every run: section.key=value (repeatable)");
  cmd->callback([o] {
    namespace fs = std::filesystem;
    const fs::path out = o->out;
    fs::create_directories(out);
    if (!o->real.empty()) {
      const nlohmann::json j = real_sequence(o->real, o->overrides, o->max_frames, out);
      write_file_atomically(out / "dense_bench_real.json", j.dump(2) + "\n", "benchmark results");
      return;
    }
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
