#include "report/process_pool.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <map>
#include <thread>

#include "core/error.hpp"

extern char** environ;

namespace varslam::report {
namespace {

using Clock = std::chrono::steady_clock;

struct Running {
  std::size_t index = 0;
  Clock::time_point start;
  bool killed = false;  // by the timeout
};

// Spawns one task with stdout+stderr redirected to its log; returns the pid or -1 (error filled in).
pid_t spawn_task(const ProcessTask& task, std::string& error) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  const std::string log = task.log_file.empty() ? std::string("/dev/null") : task.log_file.string();
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);

  std::vector<char*> args;
  for (const auto& a : task.argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, args.front(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    error = "cannot start " + task.argv.front() + ": " + std::strerror(rc);
    return -1;
  }
  return pid;
}

}  // namespace

std::vector<ProcessOutcome> run_processes(const std::vector<ProcessTask>& tasks, std::size_t max_parallel,
                                          const ProcessProgress& progress) {
  using State = ProcessOutcome::State;
  std::vector<ProcessOutcome> out(tasks.size());
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (tasks[i].argv.empty()) throw InputError("run_processes: task " + std::to_string(i) + " has no program");
    for (const std::size_t d : tasks[i].after)
      if (d >= i) throw InputError("run_processes: task " + std::to_string(i) + " depends on a later task");
  }
  max_parallel = std::max<std::size_t>(1, max_parallel);
  std::map<pid_t, Running> running;
  std::size_t finished = 0;
  auto finish = [&](std::size_t i) {
    ++finished;
    if (progress) progress(i, out[i], finished);
  };

  while (finished < tasks.size()) {
    // Start (or skip) every ready task, in index order, while slots are free.
    for (std::size_t i = 0; i < tasks.size() && running.size() < max_parallel; ++i) {
      if (out[i].state != State::NotRun) continue;
      bool ready = true, blocked = false;
      for (const std::size_t d : tasks[i].after) {
        if (out[d].state == State::Failed || out[d].state == State::Skipped) blocked = true;
        else if (out[d].state != State::Succeeded) ready = false;
      }
      if (blocked) {
        out[i].state = State::Skipped;
        out[i].error = "skipped: a task it needs failed";
        finish(i);
        continue;
      }
      if (!ready) continue;
      out[i].state = State::Running;
      const pid_t pid = spawn_task(tasks[i], out[i].error);
      if (pid < 0) {
        out[i].state = State::Failed;  // not retried
        finish(i);
        continue;
      }
      running[pid] = {i, Clock::now()};
    }
    if (running.empty()) {
      if (finished < tasks.size()) {
        // Nothing runs and nothing could start: only possible when the remaining tasks were all just skipped
        // in this pass; loop again to settle them.
        continue;
      }
      break;
    }
    int status = 0;
    pid_t pid = -1;
    // Poll (20 ms) rather than block, so children past their timeout can be killed.
    while (true) {
      pid = waitpid(-1, &status, WNOHANG);
      if (pid > 0) break;
      if (pid < 0 && errno != EINTR)
        throw InputError(std::string("run_processes: waitpid failed: ") + std::strerror(errno));
      const auto now = Clock::now();
      for (auto& [child, r] : running) {
        const double limit = tasks[r.index].timeout_seconds;
        if (limit > 0 && !r.killed && std::chrono::duration<double>(now - r.start).count() > limit) {
          kill(child, SIGKILL);
          r.killed = true;
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;  // not ours (a child the caller started otherwise)
    const std::size_t i = it->second.index;
    const bool killed = it->second.killed;
    ProcessOutcome& o = out[i];
    o.wall_seconds = std::chrono::duration<double>(Clock::now() - it->second.start).count();
    if (WIFEXITED(status)) {
      o.exit_code = WEXITSTATUS(status);
    } else if (WIFSIGNALED(status)) {
      o.exit_code = 128 + WTERMSIG(status);
      o.error = std::string("killed by signal ") + std::to_string(WTERMSIG(status));
    }
    running.erase(it);
    if (killed) o.error = "timed out after " + std::to_string(tasks[i].timeout_seconds) + " s";
    o.state = o.exit_code == 0 && !killed ? State::Succeeded : State::Failed;
    if (o.state == State::Failed && o.error.empty()) o.error = "exit code " + std::to_string(o.exit_code);
    finish(i);
  }
  return out;
}

std::filesystem::path self_executable() {
  std::error_code ec;
  auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw InputError("/proc/self/exe: cannot find the running executable: " + ec.message());
  return p;
}

std::string shell_quote(const std::string& arg) {
  const bool plain = !arg.empty() && std::all_of(arg.begin(), arg.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::strchr("-_./=,:+@%", c) != nullptr;
  });
  if (plain) return arg;
  std::string q = "'";
  for (const char c : arg) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string shell_join(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) {
    if (!s.empty()) s += ' ';
    s += shell_quote(a);
  }
  return s;
}

}  // namespace varslam::report
