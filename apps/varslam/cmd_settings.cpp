// `varslam settings`: every settings key with its default, valid values and meaning (the registry).
#include <fmt/format.h>

#include "commands.hpp"
#include "io/settings_registry.hpp"

namespace varslam::cli {

void add_settings_command(CLI::App& app) {
  auto markdown = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand("settings", "List every settings key with its default, valid values and meaning");
  cmd->add_flag("--markdown", *markdown, "Print the reference as Markdown (docs/settings.md)");
  cmd->callback([markdown] { fmt::print("{}", *markdown ? settings_reference_markdown() : settings_reference_text()); });
}

}  // namespace varslam::cli
