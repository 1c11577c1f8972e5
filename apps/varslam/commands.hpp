#pragma once
// Each subcommand of the `varslam` CLI lives in its own cmd_<name>.cpp and registers itself here.
#include <CLI/CLI.hpp>

namespace varslam::cli {

void add_run_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_synth_command(CLI::App& app);
void add_demo_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_report_command(CLI::App& app);
void add_settings_command(CLI::App& app);

}  // namespace varslam::cli
