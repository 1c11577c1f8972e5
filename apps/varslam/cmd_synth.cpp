// `varslam synth`: generate a synthetic dynamic RGB-D sequence in the TUM layout.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstdio>

#include "cli_common.hpp"
#include "core/error.hpp"
#include "commands.hpp"
#include "synth/synth.hpp"

namespace varslam::cli {

void add_synth_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("synth", "Generate a synthetic dynamic-scene RGB-D sequence (TUM layout)");
  struct Options {
    synth::SynthConfig cfg;
    std::string out;
    std::string path;
    bool list = false;
    bool no_preview = false;
    bool hide_movers = false;
    std::string sensor = "default";
    std::vector<std::string> sensor_set;
  };
  auto opt = std::make_shared<Options>();
  cmd->add_option("--scenario", opt->cfg.scenario, "static | walking | unknown_box | obstructing_box | balloon | mixed | large_box | large_box_people")
      ->capture_default_str();
  cmd->add_option("--seconds", opt->cfg.seconds, "Sequence length in seconds")
      ->capture_default_str()
      ->check(finite_range(0.0, 3600.0, true));
  cmd->add_option("--seed", opt->cfg.seed, "Random seed (same seed = identical files)")->capture_default_str();
  cmd->add_option("--path", opt->path, "Camera path: TUM groundtruth file or a folder holding groundtruth.txt "
                                       "(default: built-in real excerpt of TUM fr2/desk_with_person)");
  cmd->add_option("--path-start", opt->cfg.path_start, "Seconds into the path where the sequence starts")
      ->check(finite_range(0.0, 1e6))
      ->capture_default_str();
  cmd->add_option("--out", opt->out, "Output folder (default: synth_<scenario>_<seed>)")->check(kNonEmptyPath);
  cmd->add_flag("--no-preview", opt->no_preview, "Do not write preview.png");
  cmd->add_flag("--hide-movers", opt->hide_movers,
                "Debug: render the scenario's world without its movers (identical to 'static')");
  cmd->add_option("--box-miss", opt->cfg.box_miss_rate, "Share of person boxes left out, like detector misses")
      ->check(finite_range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--box-jitter", opt->cfg.box_jitter_px, "Gaussian jitter of person box edges in pixels")
      ->check(finite_range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--sensor", opt->sensor,
                  "default: per-pixel depth noise, holes, blur, exposure drift | kinect1: also the real-sensor effects "
                  "measured on the 7-Scenes kitchen (disparity steps, smooth noise, rolling shutter, distortion, "
                  "colour/depth offset, intrinsics error; docs/synth.md)")
      ->check(CLI::IsMember({"default", "kinect1"}))
      ->capture_default_str();
  cmd->add_option("--sensor-set", opt->sensor_set,
                  "KEY=VALUE: one real-sensor effect, after --sensor (keys as in scenario.json's sensor.real)")
      ->take_all();
  cmd->add_flag("--list", opt->list, "Print the scenario names and exit");
  cmd->callback([opt] {
    if (opt->list) {
      for (const auto& n : synth::scenario_names()) fmt::print("{}\n", n);
      return;
    }
    synth::SynthConfig cfg = opt->cfg;
    cfg.path_file = opt->path;
    cfg.preview = !opt->no_preview;
    cfg.render_movers = !opt->hide_movers;
    if (opt->sensor == "kinect1") cfg.real = synth::kinect1_sensor();
    for (const std::string& kv : opt->sensor_set) {
      const auto eq = kv.find('=');
      if (eq == std::string::npos || eq == 0)
        throw InputError(fmt::format("--sensor-set '{}': expected KEY=VALUE", kv));
      synth::set_sensor_effect(cfg.real, kv.substr(0, eq), kv.substr(eq + 1));
    }
    const std::filesystem::path out =
        opt->out.empty() ? std::filesystem::path(fmt::format("synth_{}_{}", cfg.scenario, cfg.seed)) : std::filesystem::path(opt->out);
    cfg.progress = [](std::size_t done, std::size_t total) {
      if (done % 30 == 0 || done == total) {
        std::fprintf(stderr, "\rsynth: %zu / %zu frames", done, total);
        if (done == total) std::fprintf(stderr, "\n");
      }
    };
    const synth::SynthSummary s = synth::generate(cfg, out);
    fmt::print("synth: {} frames of '{}' in {:.1f} s ({:.1f} frames/s) -> {}\n", s.frames, cfg.scenario,
               s.seconds_taken, static_cast<double>(s.frames) / s.seconds_taken, std::filesystem::absolute(s.dir).string());
    fmt::print("synth: {} people, {} unknown movers, {} person boxes ({} frames with a person in view)\n", s.people,
               s.unknown_movers, s.person_boxes, s.frames_with_person);
  });
}

}  // namespace varslam::cli
