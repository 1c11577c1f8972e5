#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <opencv2/imgcodecs.hpp>
#include <system_error>

#include "core/error.hpp"
#include "io/file_problem.hpp"

namespace varslam {
namespace {

[[noreturn]] void cannot_write(const std::filesystem::path& file, const std::string& what, int err) {
  throw InputError(fmt::format("{}: cannot write the {}: {}", file.string(), what, describe_errno(err)));
}

// Writes all of `content` to `fd`; 0 or the errno of the failure (ENOSPC often shows only at close).
int write_all_and_close(int fd, const std::string& content) {
  std::size_t done = 0;
  while (done < content.size()) {
    const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      return err;
    }
    done += static_cast<std::size_t>(n);
  }
  return ::close(fd) == 0 ? 0 : errno;
}

bool is_device_or_pipe(const std::filesystem::path& file) {
  std::error_code ec;
  const auto st = std::filesystem::status(file, ec);
  return std::filesystem::exists(st) && !std::filesystem::is_regular_file(st) && !std::filesystem::is_directory(st);
}

}  // namespace

void write_file_atomically(const std::filesystem::path& file, const std::string& content, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw InputError(fmt::format("{}: cannot write the {}: it is a folder", file.string(), what));
  if (is_device_or_pipe(file)) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) cannot_write(file, what, errno);
    if (const int err = write_all_and_close(fd, content)) cannot_write(file, what, err);
    return;
  }
  const std::filesystem::path tmp = file.string() + fmt::format(".tmp{}", ::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) cannot_write(file, what, errno);
  if (const int err = write_all_and_close(fd, content)) {
    std::filesystem::remove(tmp, ec);
    cannot_write(file, what, err);
  }
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    const int err = ec.value();
    std::filesystem::remove(tmp, ec);
    cannot_write(file, what, err);
  }
}

void write_image_atomically(const std::filesystem::path& file, const cv::Mat& image, const std::string& what,
                            const std::vector<int>& params) {
  std::vector<unsigned char> bytes;
  try {
    if (!cv::imencode(file.extension().string(), image, bytes, params))
      throw InputError(fmt::format("{}: cannot write the {}: the image cannot be encoded", file.string(), what));
  } catch (const cv::Exception& e) {
    throw InputError(fmt::format("{}: cannot write the {}: {}", file.string(), what, e.what()));
  }
  write_file_atomically(file, std::string(bytes.begin(), bytes.end()), what);
}

}  // namespace varslam
