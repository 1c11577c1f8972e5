// varslam_node: varslam as a ROS 1 node (node.hpp). Bad parameters stop it with the message and exit code 2.
#include <cstdio>
#include <ros/ros.h>

#include "node.hpp"

int main(int argc, char** argv) {
  // rosconsole writes INFO lines to stdout; redirected to a file (roslaunch, a service manager) stdout is fully
  // buffered, and a user tailing the log would see nothing until the node exits. One line at a time instead.
  std::setvbuf(stdout, nullptr, _IOLBF, BUFSIZ);
  ros::init(argc, argv, "varslam");
  ros::NodeHandle nh, pnh("~");
  // varslam's own log lines go through rosconsole, with the node's.
  varslam::set_log_sink(
      [](varslam::LogLevel level, const std::string& line) {
        switch (level) {
          case varslam::LogLevel::Error:
            ROS_ERROR("%s", line.c_str());
            break;
          case varslam::LogLevel::Warn:
            ROS_WARN("%s", line.c_str());
            break;
          case varslam::LogLevel::Info:
            ROS_INFO("%s", line.c_str());
            break;
          default:
            ROS_DEBUG("%s", line.c_str());
            break;
        }
      },
      varslam::LogLevel::Info);
  try {
    varslam_ros::VarslamNode node(nh, pnh);
    ros::spin();
  } catch (const varslam::InputError& e) {
    ROS_FATAL("%s", e.what());
    return 2;
  }
  return 0;
}
