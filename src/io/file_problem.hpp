#pragma once
// What went wrong with a file, in words a user acts on: "the disk is full", "permission denied". Every reader and
// writer names its problems through here, so a full disk or a missing permission reads the same everywhere.
#include <filesystem>
#include <string>
#include <system_error>

namespace varslam {

/// Clear words for an errno value: ENOSPC "the disk is full (no space left on the device)", EACCES "permission
/// denied", ELOOP "a loop of symbolic links", ...; strerror for the rest.
std::string describe_errno(int err);

/// describe_errno for an error_code (std::filesystem's errors).
std::string describe_error(const std::error_code& ec);

/// "<path>: <clear words>" for an error std::filesystem threw (the operation's name left out: users act on the
/// path and the problem).
std::string describe_filesystem_error(const std::filesystem::filesystem_error& e);

/// Throws InputError "<file>: cannot write the <what>: <why>" unless `file` could be written now: its folder
/// exists and takes new files (the atomic writer creates a temporary beside it), and it is not a folder. Called
/// before long work, so an output that cannot be written is found before the work, not after it.
void check_output_file(const std::filesystem::path& file, const std::string& what);

}  // namespace varslam
