// varslam: RGB-D visual SLAM for dynamic scenes. One CLI, one subcommand per job.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <exception>
#include <filesystem>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "io/file_problem.hpp"

int main(int argc, char** argv) {
  // Logs and errors go to stderr; stdout carries what a command prints (summaries, `settings`, `eval`).
  spdlog::set_default_logger(spdlog::stderr_color_mt("varslam"));
  CLI::App app{"varslam: RGB-D visual SLAM that stays accurate where things move"};
  app.require_subcommand(1);
  // Subcommands run inside parse(), so the log level is set as soon as the flag is parsed.
  app.add_flag_function(
      "-v,--verbose",
      [](std::int64_t count) { spdlog::set_level(count > 1 ? spdlog::level::trace : spdlog::level::debug); },
      "Debug logging (-vv: also per-frame decisions that changed nothing)");
  varslam::cli::add_demo_command(app);
  varslam::cli::add_run_command(app);
  varslam::cli::add_eval_command(app);
  varslam::cli::add_synth_command(app);
  varslam::cli::add_bench_command(app);
  varslam::cli::add_report_command(app);
  varslam::cli::add_settings_command(app);
  varslam::cli::add_view_command(app);
  varslam::cli::add_bag_command(app);
  varslam::cli::add_dense_bench_command(app);
  varslam::cli::add_sensor_stats_command(app);
  // Runs once the whole command line is parsed, before the subcommand's own callback starts any work.
  app.parse_complete_callback([&app] { varslam::cli::check_flag_needs(app); });
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help is a ParseError with code 0; every other one is bad input, like a bad setting (exit 2).
    return app.exit(e) == 0 ? 0 : varslam::cli::kExitInputError;
  } catch (const varslam::cli::CommandFailed& e) {
    spdlog::error("{}", e.what());
    return e.code;
  } catch (const varslam::InputError& e) {
    spdlog::error("{}", e.what());
    return varslam::cli::kExitInputError;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the system refused (permission, a symlink loop, a full disk): the path's problem, not a bug.
    spdlog::error("{}", varslam::describe_filesystem_error(e));
    return varslam::cli::kExitInputError;
  } catch (const std::exception& e) {
    spdlog::error("internal error: {}", e.what());
    return varslam::cli::kExitInternalError;
  }
  return 0;
}
