#pragma once
// Which topics of a bag are the colour images, the depth images, the colour camera's CameraInfo and the depth
// unit: chosen by message type and name where the user named none (bag_dataset.hpp lists the layouts).
#include <string>
#include <vector>

namespace varslam::bag {

struct TopicEntry {
  std::string name, type;
  std::size_t messages = 0;
};

struct ChosenTopics {
  std::string rgb, depth;
  std::string info;         // CameraInfo of the colour images; empty when the bag has none
  std::string depth_units;  // a Float32 giving metres per depth unit (RealSense); empty when none
};

/// Throws InputError (naming `bag` and the --topic-* option to use) when no image topic exists (listing the
/// topics found), when a named topic is missing or of the wrong type, or when two candidates rank equally.
ChosenTopics choose_topics(const std::string& bag, const std::vector<TopicEntry>& topics, const std::string& rgb,
                           const std::string& depth, const std::string& info);

}  // namespace varslam::bag
