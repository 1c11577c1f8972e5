#pragma once
// TUM-style frame lists ("timestamp path" per line, '#' comments) and rgb/depth association by timestamp.
#include <filesystem>
#include <string>
#include <vector>

namespace varslam {

struct ListEntry {
  double timestamp = 0.0;
  std::string path;   // as written in the list (relative to the dataset folder)
  std::string where;  // "<list file>:<line>", for messages about this entry
};

/// One rgb image and its depth partner.
struct FramePair {
  ListEntry rgb;
  ListEntry depth;
};

/// Reads a "timestamp path" list. Throws InputError naming file:line on a malformed line, a non-finite
/// timestamp, or a timestamp that is not strictly after the previous one.
std::vector<ListEntry> read_frame_list(const std::filesystem::path& file);

/// Reads "t_rgb rgb_path t_depth depth_path" lines (the TUM associate tool's output), same checks on t_rgb.
std::vector<FramePair> read_associations(const std::filesystem::path& file);

/// Pairs each rgb entry with the depth entry nearest in time, if closer than max_dt. One-to-one, greedy by
/// smallest time difference (like TUM's associate.py); the result is in rgb order. Both lists must be sorted.
std::vector<FramePair> associate_frames(const std::vector<ListEntry>& rgb, const std::vector<ListEntry>& depth,
                                        double max_dt = 0.02);

}  // namespace varslam
