// `varslam bench`: scenarios x paths x seeds x configurations, each run an isolated child process.
#include "commands.hpp"

namespace varslam::cli {

void add_bench_command(CLI::App& app) {
  app.add_subcommand("bench", "Run the benchmark matrix (work in progress)");
}

}  // namespace varslam::cli
