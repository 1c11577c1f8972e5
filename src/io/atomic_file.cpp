#include "io/atomic_file.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <fstream>
#include <system_error>

#include "core/error.hpp"

namespace varslam {

void write_file_atomically(const std::filesystem::path& file, const std::string& content, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw InputError(fmt::format("{}: cannot write the {}: it is a folder", file.string(), what));
  const std::filesystem::path tmp = file.string() + fmt::format(".tmp{}", ::getpid());
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw InputError(fmt::format("{}: cannot write the {}", file.string(), what));
    out << content;
    out.flush();
    if (!out) {
      std::filesystem::remove(tmp, ec);
      throw InputError(fmt::format("{}: error while writing the {}", file.string(), what));
    }
  }
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(fmt::format("{}: cannot write the {}: {}", file.string(), what, ec.message()));
  }
}

}  // namespace varslam
