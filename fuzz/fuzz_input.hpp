#pragma once
// Shared by the fuzz harnesses: the readers take file paths, so each input is
// written to a file first, and a reader may only fail with InputError (a
// message for the user); anything else is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace varslam::fuzz {

/// A folder of this process's own under the temp directory (several fuzz jobs
/// may run at once).
inline const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("varslam_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

inline std::filesystem::path write_input(std::string_view name, const std::uint8_t* data, std::size_t size) {
  const auto file = scratch_dir() / std::string(name);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return file;
}

/// A broken promise of a reader's contract (what it returned, not how it
/// failed): abort so libFuzzer keeps the input.
[[noreturn]] inline void contract_broken(const char* what) {
  std::fprintf(stderr, "contract broken: %s\n", what);
  std::abort();
}

#define VARSLAM_FUZZ_EXPECT(cond)                         \
  do {                                                    \
    if (!(cond)) ::varslam::fuzz::contract_broken(#cond); \
  } while (0)

}  // namespace varslam::fuzz
