// `varslam eval`: ATE / RPE / correct rate of an estimated trajectory against ground truth (TUM files).
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "eval/eval_report.hpp"
#include "io/atomic_file.hpp"
#include "io/file_problem.hpp"
#include "io/frame_list.hpp"
#include "io/trajectory_io.hpp"
#include "mapfile/map_file.hpp"

namespace varslam::cli {
namespace {

struct EvalArgs {
  std::string gt;
  std::string est;
  std::string json;
  std::string plot;
  double max_diff = 0.02;
  double offset = 0.0;
  double delta = 1.0;
  bool scale = false;
  bool per_pair = false;
  std::optional<std::size_t> frame_count;
  std::string frame_list;
  std::string map;
};

void run_eval(const EvalArgs& a) {
  if (!a.json.empty()) check_output_file(a.json, "JSON report");
  if (!a.plot.empty()) check_output_file(a.plot, "plot");
  const Trajectory gt = read_tum_trajectory(a.gt);
  const Trajectory est = read_tum_trajectory(a.est);
  EvalOptions options;
  options.ate.max_difference = a.max_diff;
  options.ate.offset = a.offset;
  options.ate.with_scale = a.scale;
  options.rpe_delta_seconds = a.delta;
  if (!a.map.empty()) {
    // A run localized in a saved map, measured in that map's own alignment to ground truth.
    const mapfile::SavedMap m = mapfile::load_map_file(a.map);
    if (!m.groundtruth_alignment)
      throw InputError(a.map + ": the map has no alignment to ground truth (the run that built it had none)");
    if (a.scale) throw InputError("--map and --scale: the map's alignment is rigid");
    Alignment fixed;
    fixed.R = m.groundtruth_alignment->linear();
    fixed.t = m.groundtruth_alignment->translation();
    options.ate.fixed_alignment = fixed;
  }
  options.frame_count = a.frame_count;
  if (!a.frame_list.empty()) {
    // Frames that could have been evaluated: those with ground truth in reach.
    std::vector<double> stamps;
    for (const auto& e : read_frame_list(a.frame_list)) stamps.push_back(e.timestamp);
    options.frame_count = count_frames_with_ground_truth(stamps, gt, a.max_diff);
  }
  EvalSummary summary;
  try {
    summary = evaluate_trajectory(gt, est, options);
  } catch (const InputError& e) {
    throw InputError(a.est + " vs " + a.gt + ": " + e.what());
  }
  std::fputs(format_eval_table(summary).c_str(), stdout);

  if (!a.json.empty()) {
    nlohmann::json j = eval_to_json(summary, a.per_pair);
    j["files"] = {{"gt", a.gt}, {"est", a.est}};
    write_file_atomically(a.json, j.dump(2) + "\n", "JSON report");
    std::printf("wrote %s\n", a.json.c_str());
  }
  if (!a.plot.empty()) {
    for (const auto& p : write_eval_plots(gt, summary, a.plot)) std::printf("wrote %s\n", p.string().c_str());
  }
}

}  // namespace

void add_eval_command(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  auto* cmd = app.add_subcommand("eval", "ATE (TUM evaluate_ate), RPE per second and correct rate of a trajectory");
  cmd->add_option("--gt", args->gt, "Ground-truth trajectory (TUM format)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--est", args->est, "Estimated trajectory (TUM format)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--json", args->json, "Write every figure as JSON here")->check(kNonEmptyPath);
  cmd->add_option("--plot", args->plot,
                  "Write the top view here (.svg or .png) and the error over time as <stem>_ate_error.<ext>")
      ->check(kNonEmptyPath);
  cmd->add_option("--max-diff", args->max_diff, "Association window in seconds (strict)")
      ->capture_default_str()
      ->check(finite_range(0.0, 1e6, true));
  cmd->add_option("--map", args->map,
                  "Evaluate in this saved map's alignment to ground truth instead of a fresh one (a run localized in "
                  "the map)");
  cmd->add_option("--offset", args->offset, "Seconds added to the estimate's timestamps")
      ->capture_default_str()
      ->check(finite_range(-1e10, 1e10));
  cmd->add_option("--delta", args->delta, "RPE interval in seconds")
      ->capture_default_str()
      ->check(finite_range(0.0, 1e6, true));
  cmd->add_flag("--scale", args->scale, "Align with scale (Sim(3), for monocular estimates)");
  cmd->add_flag("--per-pair", args->per_pair, "Also put each pair's ATE error into the JSON");
  auto* count = cmd->add_option("--frames", args->frame_count,
                                "Correct-rate denominator: number of input frames (default: estimate poses)");
  cmd->add_option("--frame-list", args->frame_list,
                  "Correct-rate denominator from a frame list (e.g. rgb.txt): its frames with ground truth in reach")
      ->check(CLI::ExistingFile)
      ->excludes(count);
  cmd->callback([args] { run_eval(*args); });
}

}  // namespace varslam::cli
