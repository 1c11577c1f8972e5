#pragma once
// Where and with what a benchmark ran: for results.json and BENCHMARKS.md, so numbers can be compared fairly.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace varslam::report {

struct MachineInfo {
  unsigned cores = 0;        // online processors
  std::string cpu_model;     // /proc/cpuinfo "model name"
  double memory_gb = 0.0;    // MemTotal
  double load_average = 0.0; // 1-minute load when sampled (other users of the machine show up here)
  std::string os;            // uname sysname release machine
};
MachineInfo sample_machine_info();
nlohmann::json to_json(const MachineInfo& m);
/// Back from to_json (a benchmark plan records where it was planned); missing keys stay empty.
MachineInfo machine_info_from_json(const nlohmann::json& j);
/// "2 cores, Intel(R) Xeon(R) ..., 7.8 GB" style line.
std::string describe(const MachineInfo& m);

/// `git describe --always --dirty --tags` of the source tree that holds `start` (searched upwards for .git);
/// "unknown" when there is none or git is missing.
std::string git_describe(const std::filesystem::path& start);

}  // namespace varslam::report
