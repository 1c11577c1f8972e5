#pragma once
// Per-frame detection boxes as text: one box per line, "timestamp label score x y w h" (pixels),
// '#' comments. Written by `varslam synth` (ground-truth boxes) and read by the `boxes` detector source.
#include <filesystem>
#include <map>

#include "core/detection.hpp"

namespace varslam {

/// Boxes grouped by timestamp (frames without boxes have no entry).
using BoxesByTime = std::map<double, Detections>;

/// Throws InputError naming the file and line on a malformed line.
BoxesByTime read_boxes_file(const std::filesystem::path& file);
void write_boxes_file(const BoxesByTime& boxes, const std::filesystem::path& file);
/// Boxes of the frame whose timestamp is nearest to t within max_dt; empty if none.
Detections boxes_near(const BoxesByTime& boxes, double t, double max_dt = 0.02);

}  // namespace varslam
