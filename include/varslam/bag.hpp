#pragma once
// ROS 1 bags as input for a library session (C++17): the reader `varslam run --dataset FILE.bag` uses, with no ROS
// master needed. Topics are found by type and name (TUM RGB-D, Bonn, RealSense, OpenLORIS layouts) unless given;
// the camera comes from the colour topic's CameraInfo unless a settings file is given. See README, "On a robot".
//
//   varslam::BagReader bag("walking.bag");
//   varslam::Slam slam(bag.config());
//   for (std::size_t i = 0; i < bag.size(); ++i) { const auto f = bag.frame(i); slam.track(f.bgr, f.depth,
//   f.timestamp); }
#include <cstddef>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>
#include <varslam/config.hpp>
#include <varslam/error.hpp>
#include <varslam/types.hpp>
#include <vector>

namespace varslam {

/// Topics chosen by the caller; empty ones are found by message type and name.
struct BagTopics {
  std::string rgb, depth, info;
  std::string gt_frame;  // ground truth: the /tf poses of this child frame (empty: none)
};

struct BagFrame {
  double timestamp = 0;  // the colour image's header stamp, seconds
  cv::Mat bgr;           // CV_8UC3
  cv::Mat depth;         // CV_32FC1 metres, 0 = none, paired by nearest stamp (at most 0.02 s)
};

class BagReader {
 public:
  /// Opens and indexes the bag. Throws InputError naming the bag and the problem: not a bag, truncated or unindexed
  /// (with the `rosbag reindex` command), no image topic (listing those found), an ambiguous or missing topic, or a
  /// build without ROS bag support.
  explicit BagReader(const std::string& file, const BagTopics& topics = {}, const std::string& settings_file = {});
  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  /// The settings for a session on this bag: the settings file's, else the camera of CameraInfo and the depth unit.
  const Config& config() const;
  std::size_t size() const;
  /// Decodes frame i (thread-safe). Throws InputError naming the message on broken data.
  BagFrame frame(std::size_t i) const;
  /// The ground truth of BagTopics::gt_frame (camera-to-world poses), empty without one.
  std::vector<TimedPose> groundtruth() const;
  /// True when this build reads bags (ROS 1 found when varslam was built).
  static bool supported();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace varslam
