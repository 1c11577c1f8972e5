#pragma once
// The node's private parameters: its own (frames, topics, files) and, under the settings registry's names with '/'
// for '.', every varslam setting (~tracking/kernel: huber), checked as `varslam run --set` checks them.
#include <ros/node_handle.h>

#include <string>
#include <varslam/config.hpp>

namespace varslam_ros {

struct NodeParams {
  std::string settings_file;       // ~settings_file: a varslam or ORB-SLAM3 settings file (else CameraInfo)
  std::string map_frame = "map";   // ~map_frame
  std::string camera_frame;        // ~camera_frame (default: the colour image's frame_id)
  std::string odom_frame;          // ~odom_frame: publish map -> odom (from odom -> camera on /tf), not map -> camera
  std::string map_file;            // ~map_file: what ~save_map writes and ~load_map reads
  bool load_map_at_start = false;  // ~load_map_at_start: start in ~map_file
  bool localization_only = false;  // ~localization_only (with a loaded map)
  bool realtime = true;            // ~realtime: false = deterministic (every stage in the tracking thread)
  double depth_unit = 0.001;       // ~depth_unit: metres per step of 16-bit depth (REP 118: millimetres)
  int map_every_keyframes = 1;     // ~map_every_keyframes: publish the map points every N keyframes
  std::string stats_file;          // ~stats_file: JSON written at shutdown (frames, drops, latency)
  bool viewer = false;             // ~viewer: serve the live viewer (its address is logged)
  int viewer_port = 0;             // ~viewer_port (0: a free one)
  std::string viewer_address = "127.0.0.1";  // ~viewer_address
  // With ~dense/enabled (the dense map of the static scene): its surface on ~dense_map as a PointCloud2.
  double dense_map_rate = 1.0;  // ~dense_map_rate: clouds per second at most, (0, 30]
  int dense_map_cell = 2;       // ~dense_map_cell: one point per cube of this many voxels (1, 2, 4 or 8)
};

/// Reads the node's parameters and applies every other private parameter to `config` as a setting. Throws
/// varslam::ConfigError naming the parameter for an unknown key or a bad value.
NodeParams read_params(const ros::NodeHandle& private_nh, varslam::Config& config);

/// The settings given as parameters (applied to a Config once it exists: after the first CameraInfo).
void apply_setting_params(const ros::NodeHandle& private_nh, varslam::Config& config);

}  // namespace varslam_ros
