#pragma once
// Runs the built command line as a user would and keeps what it printed (stdout and stderr) with its exit code.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "file_text.hpp"

namespace varslam::cli_test {

inline const std::string kCli = std::string(VARSLAM_BINARY_DIR) + "/bin/varslam";

using test::slurp;

struct Outcome {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

/// `varslam ARGS`; `tag` names the log file (one per test binary and process).
inline Outcome cli(const std::string& args, const std::string& tag = "varslam_cli") {
  const std::filesystem::path log =
      std::filesystem::temp_directory_path() / (tag + "_" + std::to_string(::getpid()) + ".log");
  const int status = std::system((kCli + " " + args + " > " + log.string() + " 2>&1").c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(log)};
}

}  // namespace varslam::cli_test
