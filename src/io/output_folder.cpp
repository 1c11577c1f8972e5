#include "io/output_folder.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <set>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/file_problem.hpp"

namespace varslam {
namespace fs = std::filesystem;
namespace {

// A manifest line names a file in the folder itself: nothing with a path, nothing of ours.
bool plain_file_name(const std::string& name) {
  return !name.empty() && name.find('/') == std::string::npos && name != "." && name != ".." &&
         name.rfind(".varslam", 0) != 0;
}

std::set<std::string> read_manifest(const fs::path& dir) {
  std::set<std::string> names;
  std::ifstream in(dir / kOutputManifest);
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#' && plain_file_name(line)) names.insert(line);
  return names;
}

void write_manifest(const fs::path& dir, const std::set<std::string>& names) {
  std::string text = "# Files a varslam command wrote into this folder; the next one removes these, and only these.\n";
  for (const auto& n : names) text += n + "\n";
  write_file_atomically(dir / kOutputManifest, text, "list of output files");
}

bool exists_no_follow(const fs::path& p) {
  std::error_code ec;
  return fs::exists(fs::symlink_status(p, ec));
}

void create_folder(const fs::path& dir) {
  if (dir.empty()) throw InputError("the output folder is empty: give a folder name");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw InputError(fmt::format("{}: cannot create the output folder: {}", dir.string(),
                                 ec ? describe_error(ec) : std::string("a file of that name exists")));
}

int lock_folder(const fs::path& dir) {
  const fs::path lock = dir / ".varslam.lock";
  const int fd = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0)
    throw InputError(fmt::format("{}: cannot write into the output folder: {}", dir.string(), describe_errno(errno)));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    throw InputError(fmt::format("{}: another varslam run is writing into this folder; give this one another --out",
                                 dir.string()));
  }
  return fd;
}

// The outputs already in the folder that no varslam command listed: the user's, so the command stops here.
void refuse_files_of_the_user(const fs::path& dir, const std::vector<OutputFile>& outputs,
                              const std::set<std::string>& ours) {
  std::vector<std::string> theirs;
  for (const OutputFile& o : outputs) {
    std::error_code ec;
    if (fs::is_directory(fs::symlink_status(dir / o.name, ec)))
      throw InputError(fmt::format("{}: cannot write the {}: it is a folder", (dir / o.name).string(), o.what));
    if (exists_no_follow(dir / o.name) && !ours.count(o.name)) theirs.push_back(o.name);
  }
  if (theirs.empty()) return;
  const bool marked = exists_no_follow(dir / kOutputManifest);
  throw InputError(fmt::format(
      "{}: holds {} that no varslam run wrote there ({}); varslam would overwrite {}: give another --out, or move "
      "{} away",
      dir.string(), fmt::join(theirs, ", "),
      marked ? fmt::format("{} does not list them", kOutputManifest)
             : fmt::format("the folder has no {} list of an earlier run's files", kOutputManifest),
      theirs.size() == 1 ? "it" : "them", theirs.size() == 1 ? "it" : "them"));
}

std::size_t remove_listed(const fs::path& dir, const std::set<std::string>& names, std::set<std::string>& left) {
  std::size_t removed = 0;
  for (const auto& n : names) {
    std::error_code ec;
    const auto st = fs::symlink_status(dir / n, ec);
    if (!fs::exists(st)) continue;
    // Files only: a folder of that name is the user's.
    if (!fs::is_directory(st) && fs::remove(dir / n, ec)) {
      ++removed;
      continue;
    }
    left.insert(n);
  }
  return removed;
}

}  // namespace

OutputFolder::OutputFolder(const fs::path& dir, const std::vector<OutputFile>& outputs) {
  create_folder(dir);
  lock_fd_ = lock_folder(dir);
  try {
    const std::set<std::string> earlier = read_manifest(dir);
    refuse_files_of_the_user(dir, outputs, earlier);
    // An earlier run's files would sit beside this run's and read as its results.
    std::set<std::string> listed;
    const std::size_t removed = remove_listed(dir, earlier, listed);
    if (removed > 0)
      spdlog::info("{}: removed {} files of an earlier run (listed in {})", dir.string(), removed, kOutputManifest);
    for (const OutputFile& o : outputs) listed.insert(o.name);
    write_manifest(dir, listed);
  } catch (...) {
    ::close(lock_fd_);
    throw;
  }
}

OutputFolder::~OutputFolder() {
  ::flock(lock_fd_, LOCK_UN);
  ::close(lock_fd_);
}

std::size_t remove_earlier_outputs(const fs::path& dir) {
  std::set<std::string> left;
  return remove_listed(dir, read_manifest(dir), left);
}

void claim_output_file(const fs::path& file, const std::string& what) {
  const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
  std::set<std::string> listed = read_manifest(dir);
  const std::string name = file.filename().string();
  refuse_files_of_the_user(dir, {{name, what}}, listed);
  if (listed.insert(name).second) write_manifest(dir, listed);
}

}  // namespace varslam
