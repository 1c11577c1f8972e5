#pragma once
// Small file and time helpers the benchmark's plan, jobs and collection share.
#include <filesystem>
#include <string>

namespace varslam::report {

/// The whole file as text ("" when it cannot be read).
std::string read_text_file(const std::filesystem::path& file);
/// Writes the file whole (temporary name, then rename); InputError naming it when it cannot.
void write_text_file(const std::filesystem::path& file, const std::string& text);
/// "2026-12-03T15:21:38Z".
std::string utc_now_iso8601();

}  // namespace varslam::report
