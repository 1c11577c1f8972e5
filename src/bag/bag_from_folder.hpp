#pragma once
// Writes an RGB-D dataset folder as a ROS 1 bag (`varslam bag-from-folder`): what a robot's recording of the same
// frames would hold, in the TUM RGB-D topic layout or a RealSense recording's.
#include <filesystem>
#include <functional>
#include <string>

#include "io/dataset.hpp"
#include "io/settings.hpp"

namespace varslam::bag {

enum class BagLayout { Tum, RealSense };
enum class BagImages { Raw, Png, Jpeg };  // Png: lossless CompressedImage (colour PNG, compressedDepth PNG)

struct BagWriteOptions {
  BagLayout layout = BagLayout::Tum;
  BagImages images = BagImages::Raw;
  std::size_t first = 0, max_frames = SIZE_MAX;
  double time_offset = 0;  // added to every stamp (ground truth included): ROS time 0 means "unset"
  std::function<void(std::size_t done, std::size_t total)> progress;  // optional
};

struct BagWriteSummary {
  std::size_t frames = 0, groundtruth_poses = 0, box_frames = 0;
  std::string rgb_topic, depth_topic, info_topic;
};

/// Writes the frames of `dataset` (read with `settings`: the camera goes into CameraInfo messages, the depth factor
/// into a depth-unit topic) to `out`, with its ground truth as /tf (parent "world", child "kinect") when it has
/// one, and its person boxes (boxes.txt) as geometry_msgs/PolygonStamped on <colour namespace>/people (two corners
/// per box, z = score: what varslam_node takes as person boxes). TUM layout, raw: colour bgr8 and depth 32FC1 metres
/// exactly as the folder reader decodes them, so a deterministic run on the bag gives the folder's trajectory. Written
/// to a temporary name, then renamed.
BagWriteSummary write_bag_from_dataset(const Dataset& dataset, const Settings& settings,
                                       const std::filesystem::path& out, const BagWriteOptions& options);

}  // namespace varslam::bag
