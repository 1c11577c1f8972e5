#pragma once
// Output files appear whole or not at all: written to a temporary name beside the target, then renamed over it,
// so a crash or an interrupted run never leaves half a file under the final name.
#include <filesystem>
#include <string>

namespace varslam {

/// Writes `content` to `file` atomically; InputError naming the file (and `what` it is) when it cannot.
void write_file_atomically(const std::filesystem::path& file, const std::string& content, const std::string& what);

}  // namespace varslam
