#pragma once
// varslam as a ROS 1 node: a thin adapter over the public API (varslam::Slam). Synchronised colour + depth in,
// odometry, TF, paths, map points, keyframes, tracking state, Local BA alpha and the dense map's surface out; services to save and load the
// map, switch localization-only and reset. No SLAM logic here.
#include <geometry_msgs/PolygonStamped.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/synchronizer.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <varslam/varslam.hpp>

#include "param_config.hpp"

namespace varslam_ros {

class VarslamNode : public varslam::Listener {
 public:
  /// Throws varslam::ConfigError / InputError for bad parameters or settings (the node then stops).
  VarslamNode(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~VarslamNode() override;  // stops the tracking thread, finishes the session, writes ~stats_file

  void on_local_ba(const varslam::LocalBaInfo& info) override;

 private:
  using Clock = std::chrono::steady_clock;
  using SyncPolicy = message_filters::sync_policies::ApproximateTime<sensor_msgs::Image, sensor_msgs::Image>;
  struct Pending {
    sensor_msgs::ImageConstPtr rgb, depth;
    Clock::time_point received;
  };

  void on_images(const sensor_msgs::ImageConstPtr& rgb, const sensor_msgs::ImageConstPtr& depth);
  void on_camera_info(const sensor_msgs::CameraInfoConstPtr& info);
  void on_people(const geometry_msgs::PolygonStampedConstPtr& people);
  /// `initialpose` (RViz's "2D Pose Estimate"): the camera's pose in ~map_frame, a relocalization hint.
  void on_initial_pose(const geometry_msgs::PoseWithCovarianceStampedConstPtr& pose);
  /// The person boxes given for this image stamp on `people` (waiting briefly when a publisher exists), if any.
  std::optional<std::vector<varslam::PersonBox>> people_for(const ros::Time& stamp);
  void on_person_boxes(const varslam::PersonBoxesInfo& info) override;
  void on_colour_seen(const sensor_msgs::ImageConstPtr&) { ++colour_seen_; }
  void tracking_loop();
  void track(const Pending& p);
  void ensure_session(const sensor_msgs::Image& rgb);
  void publish_pose(const varslam::TrackedFrame& f, const std_msgs::Header& header);
  /// The transform the node puts on /tf for a pose: map -> camera, or map -> odom with ~odom_frame (empty when
  /// odom -> camera is not on /tf at that time).
  std::optional<geometry_msgs::TransformStamped> map_transform(const nav_msgs::Odometry& odom) const;
  void publish_map(const ros::Time& stamp);
  void publish_corrected_path(const ros::Time& stamp);
  /// With dense mapping: the dense map's surface on ~dense_map at ~dense_map_rate, from its own thread (the image
  /// callbacks and tracking never wait for it).
  void dense_loop();
  void publish_dense(const varslam::Slam& slam);
  void write_stats() const;

  bool save_map(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res);
  bool load_map(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res);
  bool reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res);
  bool localization_only(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res);

  ros::NodeHandle nh_, pnh_;
  varslam::Config config_;
  NodeParams params_;
  bool have_camera_ = false;  // from ~settings_file or the first CameraInfo
  std::unique_ptr<varslam::Slam> slam_;
  std::array<double, 4> intrinsics_{1, 1, 0, 0};  // fx fy cx cy of the session's camera

  message_filters::Subscriber<sensor_msgs::Image> rgb_sub_, depth_sub_;
  std::unique_ptr<message_filters::Synchronizer<SyncPolicy>> sync_;
  ros::Subscriber info_sub_, colour_count_sub_, people_sub_, initial_pose_sub_;
  ros::Publisher odom_pub_, tf_pub_, path_pub_, corrected_path_pub_, points_pub_, keyframes_pub_, state_pub_,
      alpha_pub_, people_pub_, dense_pub_;
  ros::ServiceServer save_srv_, load_srv_, reset_srv_, loc_srv_;
  // With ~odom_frame: odom -> camera comes from /tf, and map -> odom is what the node publishes.
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;

  // Frames wait here for the tracking thread: the callbacks never wait on SLAM, and no frame is dropped.
  std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<Pending> queue_;
  bool stop_ = false;
  std::thread tracker_;
  std::mutex session_mutex_;              // held by the tracking thread for each frame, and by the services
  std::atomic<int> services_waiting_{0};  // the tracking thread lets a waiting service in before its next frame
  std::unique_lock<std::mutex> lock_for_service();
  // A hint that came before the session started (under session_mutex_): given to it when it starts.
  std::optional<std::pair<varslam::Pose, double>> pending_hint_;

  // The session once it exists, for the dense map's thread (slam_ is the tracking thread's).
  std::atomic<varslam::Slam*> session_{nullptr};
  std::mutex dense_mutex_;
  std::condition_variable dense_cv_;
  bool dense_stop_ = false;
  std::thread dense_thread_;

  // Owned by the tracking thread (stats_ also read by write_stats after it stopped).
  nav_msgs::Path live_path_;
  std::size_t keyframes_since_map_ = 0;
  struct Stats {
    std::size_t synced = 0, tracked = 0, lost = 0, rejected = 0, max_queue = 0, with_people = 0;
    // Receipt of the pair to the published pose, the last kLatencyWindow frames (a node runs for days).
    static constexpr std::size_t kLatencyWindow = 100000;
    std::deque<double> latency_ms;
  } stats_;
  std::atomic<std::size_t> colour_seen_{0};
  // Person boxes by image stamp, from `people` (geometry_msgs/PolygonStamped: two corners per box, z = score).
  std::mutex people_mutex_;
  std::condition_variable people_cv_;
  std::map<ros::Time, std::vector<varslam::PersonBox>> people_;
};

}  // namespace varslam_ros
