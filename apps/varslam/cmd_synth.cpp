#include "commands.hpp"

namespace varslam::cli {

void add_synth_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("synth", "(not yet implemented)");
  cmd->callback([] {});
}

}  // namespace varslam::cli
