// `varslam demo`: the main job on the built-in default input. Generates a short synthetic dynamic scene
// (people walking, along a real recorded hand-held camera path) and runs SLAM on it, then says where
// everything went and what ATE it reached.
#include <fmt/format.h>

#include "cli_common.hpp"
#include "commands.hpp"
#include "io/dataset.hpp"
#include "synth/synth.hpp"

namespace varslam::cli {

void add_demo_command(CLI::App& app) {
  struct Opts {
    std::string out = "out/demo", scenario = "walking";
    double seconds = 10.0;
    std::uint64_t seed = 1;
    bool realtime = false;
    std::vector<std::string> overrides;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("demo", "Generate a short synthetic dynamic scene and run SLAM on it");
  cmd->add_option("--out,-o", o->out, "Output folder")->capture_default_str()->check(kNonEmptyPath);
  cmd->add_option("--scenario", o->scenario, "Synthetic scenario")->capture_default_str();
  cmd->add_option("--seconds", o->seconds, "Length of the scene")
      ->capture_default_str()
      ->check(finite_range(0.0, 3600.0, true));
  cmd->add_option("--seed", o->seed, "Random seed")->capture_default_str();
  cmd->add_flag("--realtime", o->realtime, "Real-time mode (threads) instead of deterministic");
  cmd->add_option("--set", o->overrides, "Override a setting: section.key=value (repeatable)");
  cmd->callback([o] {
    const std::filesystem::path root = o->out;
    const std::filesystem::path data = root / "sequence";
    synth::SynthConfig sc;
    sc.scenario = o->scenario;
    sc.seconds = o->seconds;
    sc.seed = o->seed;
    // Boxes like a real detector's: some frames missed, a few pixels of jitter.
    sc.box_miss_rate = 0.05;
    sc.box_jitter_px = 3.0;
    sc.progress = [](std::size_t done, std::size_t total) {
      if (done % 30 == 0 || done == total) fmt::print(stderr, "\r[synth] frame {}/{}   ", done, total);
    };
    fmt::print("Generating the '{}' scene ({} s, seed {}) into {}\n", sc.scenario, sc.seconds, sc.seed, data.string());
    const synth::SynthSummary ss = synth::generate(sc, data);
    fmt::print(stderr, "\n");
    fmt::print("  {} frames in {:.1f} s; preview: {}\n", ss.frames, ss.seconds_taken, (data / "preview.png").string());

    Settings settings = settings_for_dataset(data, std::nullopt);
    // The full system: people come from the scene's detection boxes (no model file needed), the adaptive
    // kernel handles everything else that moves. Command-line overrides come last and win.
    std::vector<std::string> overrides = {"semantic.detector=boxes",
                                          "semantic.boxes_file=" + (data / "boxes.txt").string(),
                                          "tracking.kernel=barron-fixed", "mapping.kernel=barron-adaptive"};
    overrides.insert(overrides.end(), o->overrides.begin(), o->overrides.end());
    apply_setting_overrides(settings, overrides);
    auto dataset = open_dataset(data, settings);
    run::RunOptions ro;
    ro.mode = o->realtime ? RunMode::RealTime : RunMode::Deterministic;
    fmt::print("Running SLAM on it\n");
    const run::RunSummary s = run::run_slam(*dataset, settings, ro, root / "run");
    write_report_for_run(s.out_dir, data);
    print_run_summary(s);
  });
}

}  // namespace varslam::cli
