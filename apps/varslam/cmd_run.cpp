#include "commands.hpp"

namespace varslam::cli {

void add_run_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("run", "(not yet implemented)");
  cmd->callback([] {});
}

}  // namespace varslam::cli
