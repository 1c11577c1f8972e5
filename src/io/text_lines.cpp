#include "io/text_lines.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

#include "core/error.hpp"
#include "io/file_problem.hpp"

namespace varslam {
namespace {
constexpr std::string_view kUtf8ByteOrderMark = "\xEF\xBB\xBF";
}  // namespace

bool parse_double(const std::string& token, double& out) {
  char* end = nullptr;
  out = std::strtod(token.c_str(), &end);
  return end != token.c_str() && *end == '\0';
}

void for_each_data_line(const std::filesystem::path& file, const std::string& what,
                        const std::function<void(const TextLine&)>& fn) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw InputError(fmt::format("{}: is a folder; expected a {}", file.string(), what));
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot open {}: {}", file.string(), what, describe_errno(errno)));
  std::string line;
  TextLine tl;
  tl.text = &line;
  while (std::getline(in, line)) {
    ++tl.number;
    // Editors on Windows start UTF-8 files with a byte-order mark; it is no part of the first line's text.
    if (tl.number == 1 && line.rfind(kUtf8ByteOrderMark, 0) == 0) line.erase(0, kUtf8ByteOrderMark.size());
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream ss(line);
    tl.tokens.clear();
    for (std::string t; ss >> t;) tl.tokens.push_back(t);
    tl.where = fmt::format("{}:{}", file.string(), tl.number);
    fn(tl);
  }
}

}  // namespace varslam
