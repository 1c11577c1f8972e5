#pragma once
// Whitespace-separated text files with '#' comments (frame lists, trajectories, boxes): one line reader, so
// every format reports errors as file:line the same way.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace varslam {

/// strtod on the whole token; "nan"/"inf" parse, so callers give them a precise "not finite" message instead of
/// calling the line malformed.
bool parse_double(const std::string& token, double& out);

struct TextLine {
  int number = 0;                   // 1-based line number
  const std::string* text = nullptr;  // the raw line
  std::vector<std::string> tokens;
  std::string where;                // "file:line" for error messages
};

/// Calls fn for every line that is neither blank nor a '#' comment (a UTF-8 byte-order mark before the first line is
/// dropped). Throws InputError "<file>: cannot open <what>: <why>" when the file cannot be read.
void for_each_data_line(const std::filesystem::path& file, const std::string& what,
                        const std::function<void(const TextLine&)>& fn);

}  // namespace varslam
