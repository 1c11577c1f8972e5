#pragma once
// Each subcommand of the `varslam` CLI lives in its own cmd_<name>.cpp and registers itself here.
#include <CLI/CLI.hpp>

namespace varslam::cli {

/// A command that ran but failed (a run that tracked almost nothing, an interrupted run): main() exits with
/// `code` after the command printed what it has.
struct CommandFailed : std::runtime_error {
  CommandFailed(const std::string& what, int exit_code) : std::runtime_error(what), code(exit_code) {}
  int code;
};
inline constexpr int kExitInputError = 2, kExitInternalError = 3, kExitTrackingFailed = 4, kExitIncomplete = 5,
                     kExitInterrupted = 130;  // kExitIncomplete: bench collect with jobs missing

void add_run_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_synth_command(CLI::App& app);
void add_demo_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_report_command(CLI::App& app);
void add_settings_command(CLI::App& app);
void add_view_command(CLI::App& app);
void add_bag_command(CLI::App& app);
void add_dense_bench_command(CLI::App& app);
void add_sensor_stats_command(CLI::App& app);

}  // namespace varslam::cli
