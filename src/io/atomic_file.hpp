#pragma once
// Output files appear whole or not at all: written to a temporary name beside the target, then renamed over it,
// so a crash or an interrupted run never leaves half a file under the final name.
#include <filesystem>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

namespace varslam {

/// Writes `content` to `file` atomically; InputError "<file>: cannot write the <what>: <why>" when it cannot, the
/// why in clear words (a full disk, a read-only file system, a permission: io/file_problem.hpp). A device or a
/// pipe (/dev/stdout) is written in place: it cannot be renamed over.
void write_file_atomically(const std::filesystem::path& file, const std::string& content, const std::string& what);

/// Encodes `image` in the format of the file's extension (.png, .jpg) and writes it as write_file_atomically does.
void write_image_atomically(const std::filesystem::path& file, const cv::Mat& image, const std::string& what,
                            const std::vector<int>& params = {});

}  // namespace varslam
