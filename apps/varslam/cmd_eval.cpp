#include "commands.hpp"

namespace varslam::cli {

void add_eval_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("eval", "(not yet implemented)");
  cmd->callback([] {});
}

}  // namespace varslam::cli
