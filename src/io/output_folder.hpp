#pragma once
// An output folder shared with the user's own files. A command lists the files it wrote in the folder's
// .varslam-outputs; a later command removes those, and only those, before writing its own. A file it would
// overwrite that no varslam command wrote is the user's: refused, never removed.
#include <filesystem>
#include <string>
#include <vector>

namespace varslam {

/// A file a command may write into its folder: the plain name and what it is (for messages).
struct OutputFile {
  std::string name;
  std::string what;
};

/// The manifest's name inside an output folder.
inline constexpr const char* kOutputManifest = ".varslam-outputs";

/// A command's output folder for as long as the command writes into it.
class OutputFolder {
 public:
  /// Creates `dir`, holds it against a concurrent command (InputError "another varslam run is writing into this
  /// folder"), removes the files the manifest of an earlier command lists, and records `outputs` as this
  /// command's. InputError naming the folder and the files when any of `outputs` is there without the manifest
  /// listing it (the user's), and naming the file when one is a folder.
  OutputFolder(const std::filesystem::path& dir, const std::vector<OutputFile>& outputs);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

 private:
  int lock_fd_ = -1;
};

/// Removes the files `dir`'s manifest lists (nothing without one); returns how many were removed.
std::size_t remove_earlier_outputs(const std::filesystem::path& dir);

/// Before `file` is written into a folder of another command's (a report into a run folder): InputError unless
/// the file is absent or the folder's manifest lists it; afterwards it is listed.
void claim_output_file(const std::filesystem::path& file, const std::string& what);

}  // namespace varslam
