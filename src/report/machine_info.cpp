#include "report/machine_info.hpp"

#include <sys/utsname.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>

#include "report/process_pool.hpp"

namespace varslam::report {

MachineInfo sample_machine_info() {
  MachineInfo m;
  const long n = sysconf(_SC_NPROCESSORS_ONLN);
  m.cores = n > 0 ? static_cast<unsigned>(n) : 0;
  std::ifstream cpu("/proc/cpuinfo");
  for (std::string line; std::getline(cpu, line);) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) m.cpu_model = line.substr(line.find_first_not_of(' ', colon + 1));
      break;
    }
  }
  std::ifstream mem("/proc/meminfo");
  std::string key;
  double kb = 0;
  if (mem >> key >> kb && key == "MemTotal:") m.memory_gb = kb / (1024.0 * 1024.0);
  std::ifstream load("/proc/loadavg");
  load >> m.load_average;
  utsname u{};
  if (uname(&u) == 0) m.os = std::string(u.sysname) + " " + u.release + " " + u.machine;
  return m;
}

nlohmann::json to_json(const MachineInfo& m) {
  return {{"nproc", m.cores}, {"cpu_model", m.cpu_model}, {"memory_gb", m.memory_gb},
          {"load_average_1min", m.load_average}, {"os", m.os}};
}

MachineInfo machine_info_from_json(const nlohmann::json& j) {
  MachineInfo m;
  if (!j.is_object()) return m;
  m.cores = j.value("nproc", 0u);
  m.cpu_model = j.value("cpu_model", std::string());
  m.memory_gb = j.value("memory_gb", 0.0);
  m.load_average = j.value("load_average_1min", 0.0);
  m.os = j.value("os", std::string());
  return m;
}

std::string describe(const MachineInfo& m) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f GB RAM", m.memory_gb);
  return std::to_string(m.cores) + " cores, " + (m.cpu_model.empty() ? std::string("unknown CPU") : m.cpu_model) +
         ", " + buf + ", " + m.os;
}

std::string git_describe(const std::filesystem::path& start) {
  std::error_code ec;
  std::filesystem::path dir = std::filesystem::absolute(start, ec);
  while (!dir.empty() && !std::filesystem::exists(dir / ".git", ec)) {
    if (dir == dir.parent_path()) return "unknown";
    dir = dir.parent_path();
  }
  if (dir.empty()) return "unknown";
  // Read-only query; stderr dropped so a missing git or a safe.directory refusal just yields "unknown".
  const std::string cmd = "git -C " + shell_quote(dir.string()) + " describe --always --dirty --tags 2>/dev/null";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return "unknown";
  std::array<char, 256> buf{};
  std::string out;
  while (fgets(buf.data(), static_cast<int>(buf.size()), pipe)) out += buf.data();
  const int rc = pclose(pipe);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return rc == 0 && !out.empty() ? out : "unknown";
}

}  // namespace varslam::report
