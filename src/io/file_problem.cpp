#include "io/file_problem.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/error.hpp"

namespace varslam {
namespace {

[[noreturn]] void cannot_write(const std::filesystem::path& file, const std::string& what, const std::string& why) {
  throw InputError(fmt::format("{}: cannot write the {}: {}", file.string(), what, why));
}

// The folder a file goes into takes new files (a probe is created and removed).
void check_folder_takes_files(const std::filesystem::path& file, const std::string& what,
                              const std::filesystem::path& folder) {
  std::error_code ec;
  const auto st = std::filesystem::status(folder, ec);
  if (!std::filesystem::exists(st))
    cannot_write(file, what, fmt::format("the folder {} does not exist", folder.string()));
  if (!std::filesystem::is_directory(st)) cannot_write(file, what, fmt::format("{} is not a folder", folder.string()));
  const std::filesystem::path probe = folder / fmt::format(".varslam-probe-{}", ::getpid());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    const int err = errno;
    // A folder that exists but where no file can be created (/proc): "no such file" would mislead.
    const std::string why = err == ENOENT ? "it does not take new files" : describe_errno(err);
    cannot_write(file, what, fmt::format("cannot create files in {}: {}", folder.string(), why));
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

}  // namespace

std::string describe_errno(int err) {
  switch (err) {
    case ENOSPC: return "the disk is full (no space left on the device)";
    case EDQUOT: return "the disk quota is exceeded";
    case EROFS: return "the file system is read-only";
    case EACCES:
    case EPERM: return "permission denied";
    case ELOOP: return "a loop of symbolic links";
    case ENOENT: return "no such file or folder";
    case ENOTDIR: return "a part of the path is not a folder";
    case EISDIR: return "it is a folder";
    case ENAMETOOLONG: return "the name is too long";
    case EIO: return "an input/output error (a failing disk or a lost network mount)";
    default: return std::strerror(err);
  }
}

std::string describe_error(const std::error_code& ec) {
  if (ec.category() == std::generic_category() || ec.category() == std::system_category())
    return describe_errno(ec.value());
  return ec.message();
}

std::string describe_filesystem_error(const std::filesystem::filesystem_error& e) {
  std::string paths = e.path1().string();
  if (!e.path2().empty()) paths += " -> " + e.path2().string();
  return fmt::format("{}: {}", paths.empty() ? std::string("a file") : paths, describe_error(e.code()));
}

void check_output_file(const std::filesystem::path& file, const std::string& what) {
  if (file.empty()) throw InputError(fmt::format("cannot write the {}: the path is empty", what));
  std::error_code ec;
  const auto st = std::filesystem::status(file, ec);
  if (std::filesystem::is_directory(st)) cannot_write(file, what, "it is a folder");
  if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st)) {
    // A device or a pipe (/dev/null, /dev/stdout) is written in place: it only has to open.
    const int fd = ::open(file.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) cannot_write(file, what, describe_errno(errno));
    ::close(fd);
    return;
  }
  const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  check_folder_takes_files(file, what, folder);
}

}  // namespace varslam
