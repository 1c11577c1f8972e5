#include "report/bench_files.hpp"

#include <ctime>
#include <fstream>
#include <sstream>

#include "io/atomic_file.hpp"

namespace varslam::report {

std::string read_text_file(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text_file(const std::filesystem::path& file, const std::string& text) {
  write_file_atomically(file, text, "benchmark file");
}

std::string utc_now_iso8601() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace varslam::report
