#pragma once
// A ROS 1 bag as a dataset: colour and depth image topics (raw or compressed) paired by timestamp, the camera from
// a CameraInfo topic, the depth scale from the bag where it says one, ground truth from a /tf child frame. Read
// with the rosbag storage library (src/bagfile), no ROS master needed. Topic layouts found on their own: TUM RGB-D
// and Bonn (/camera/rgb/image_color, /camera/depth/image), RealSense recordings (/device_0/sensor_*/Color_0/...),
// OpenLORIS (/d400/color/image_raw, /d400/aligned_depth_to_color/image_raw), and `varslam bag-from-folder`'s.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "io/dataset.hpp"
#include "io/settings.hpp"

namespace varslam::bag {

/// Topics chosen by the user; empty = found by message type and name.
struct BagTopics {
  std::string rgb, depth, info;
  std::string gt_frame;  // ground truth: the poses of this /tf child frame (empty: none from the bag)
};

/// True for a path that names a bag file (a regular file ending in .bag), so the caller picks this reader.
bool is_bag_path(const std::filesystem::path& path);

/// True when this build reads bags (ROS 1 found at build time).
bool bag_support_built();

/// Settings for a bag: the explicit file when given (it wins over the bag, and the run logs so); otherwise the
/// camera of the colour topic's CameraInfo, the depth scale the bag states (16-bit depth without one: millimetres,
/// as ROS's REP 118 says) and defaults for the rest. Throws InputError naming the bag and the problem.
Settings settings_for_bag(const std::filesystem::path& bag, const std::optional<std::filesystem::path>& file,
                          const BagTopics& topics);

/// Opens a bag as a dataset. Images are checked against settings.camera's size; 16-bit depth is scaled by the
/// bag's depth unit where it has one, else by settings.depth_factor; 32-bit float depth is metres. Throws
/// InputError on a missing or broken bag, no image topics (naming those found), an ambiguous choice (naming the
/// --topic-* option), an unknown encoding, or depth of another size than colour.
std::unique_ptr<Dataset> open_bag_dataset(const std::filesystem::path& bag, const Settings& settings,
                                          const BagTopics& topics);

}  // namespace varslam::bag
