#pragma once
// Runs child processes (posix_spawn), at most N at a time, in dependency order. Each benchmark run must be an
// isolated process: a crash, a leak or a static cache of one run cannot touch another, and timings are per run.
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace varslam::report {

struct ProcessTask {
  std::vector<std::string> argv;   // argv[0] is the program path (no PATH search)
  std::filesystem::path log_file;  // stdout and stderr go here (truncated); empty = /dev/null
  std::vector<std::size_t> after;  // indices of tasks that must succeed first; if one fails this one is skipped
  double timeout_seconds = 0.0;    // > 0: killed (SIGKILL) after this long and counted as failed
};

struct ProcessOutcome {
  enum class State { NotRun, Running, Succeeded, Failed, Skipped } state = State::NotRun;
  int exit_code = -1;         // exit status, or 128 + signal number when killed
  double wall_seconds = 0.0;  // spawn to exit
  std::string error;          // spawn failure or the reason for skipping
};

/// Called (on the calling thread) each time a task ends or is skipped: index, outcome, tasks finished so far.
using ProcessProgress = std::function<void(std::size_t, const ProcessOutcome&, std::size_t)>;

/// Runs every task, up to max_parallel at once, starting ready tasks in index order; returns one outcome per
/// task. A task whose dependency failed is skipped. Blocks until all have ended.
std::vector<ProcessOutcome> run_processes(const std::vector<ProcessTask>& tasks, std::size_t max_parallel,
                                          const ProcessProgress& progress = {});

/// The path of the running executable (/proc/self/exe), so children are exactly this binary.
std::filesystem::path self_executable();

/// argv joined for people and shells: arguments with spaces or shell characters are single-quoted.
std::string shell_join(const std::vector<std::string>& argv);
/// One argument single-quoted for /bin/sh.
std::string shell_quote(const std::string& arg);

}  // namespace varslam::report
