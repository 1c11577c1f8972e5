#include "commands.hpp"

namespace varslam::cli {

void add_demo_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "(not yet implemented)");
  cmd->callback([] {});
}

}  // namespace varslam::cli
