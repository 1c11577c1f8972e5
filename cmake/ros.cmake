# ROS 1 from Debian's packages (scripts/setup.sh installs them): the bag reader (src/bagfile) and the node
# (ros/varslam_node). Both are built only when the packages are found; without them `varslam run` on a .bag file
# says how to get them. ROS 1 message headers do not compile as C++20, so these targets are C++17 and talk to the
# rest of varslam through headers without ROS types.
option(VARSLAM_WITH_ROS "Build the ROS bag reader and the ROS node when ROS 1 is installed" ON)
set(VARSLAM_HAVE_ROSBAG OFF)
set(VARSLAM_HAVE_ROSNODE OFF)
if(NOT VARSLAM_WITH_ROS)
  return()
endif()

find_package(PkgConfig REQUIRED)
pkg_check_modules(ROSCPP QUIET IMPORTED_TARGET roscpp roscpp_serialization rostime cpp_common)
find_library(ROSBAG_STORAGE_LIB rosbag_storage)
find_library(CONSOLE_BRIDGE_LIB console_bridge)
find_path(ROSBAG_INCLUDE_DIR rosbag/bag.h)
find_path(TF2_MSGS_INCLUDE_DIR tf2_msgs/TFMessage.h)
find_path(SENSOR_MSGS_INCLUDE_DIR sensor_msgs/Image.h)
# Debian's rosbag/bag.h includes <pluginlib/class_loader.hpp>, which its packages install one folder deeper (with
# the ROS 2 helpers it includes in turn).
find_path(PLUGINLIB_INCLUDE_DIR pluginlib/class_loader.hpp PATH_SUFFIXES pluginlib)
find_path(CLASS_LOADER_INCLUDE_DIR class_loader/class_loader.hpp PATH_SUFFIXES class_loader)
find_path(RCPPUTILS_INCLUDE_DIR rcpputils/shared_library.hpp PATH_SUFFIXES rcpputils)
find_path(RCUTILS_INCLUDE_DIR rcutils/types.h PATH_SUFFIXES rcutils)
find_path(AMENT_INDEX_INCLUDE_DIR ament_index_cpp/get_package_prefix.hpp PATH_SUFFIXES ament_index_cpp)
if(ROSCPP_FOUND AND ROSBAG_STORAGE_LIB AND CONSOLE_BRIDGE_LIB AND ROSBAG_INCLUDE_DIR AND TF2_MSGS_INCLUDE_DIR
   AND SENSOR_MSGS_INCLUDE_DIR AND PLUGINLIB_INCLUDE_DIR AND CLASS_LOADER_INCLUDE_DIR AND RCPPUTILS_INCLUDE_DIR
   AND RCUTILS_INCLUDE_DIR AND AMENT_INDEX_INCLUDE_DIR)
  set(VARSLAM_HAVE_ROSBAG ON)
  add_library(varslam_ros_deps INTERFACE)
  set_target_properties(varslam_ros_deps PROPERTIES EXPORT_NAME ros_deps)
  target_include_directories(varslam_ros_deps SYSTEM INTERFACE ${ROSBAG_INCLUDE_DIR} ${PLUGINLIB_INCLUDE_DIR}
    ${CLASS_LOADER_INCLUDE_DIR} ${RCPPUTILS_INCLUDE_DIR} ${RCUTILS_INCLUDE_DIR} ${AMENT_INDEX_INCLUDE_DIR})
  target_link_libraries(varslam_ros_deps INTERFACE ${ROSBAG_STORAGE_LIB} ${CONSOLE_BRIDGE_LIB} PkgConfig::ROSCPP)
  message(STATUS "varslam: ROS 1 found: bag input on")
else()
  message(STATUS "varslam: ROS 1 bag libraries not found (librosbag-storage-dev, libroscpp-dev, libsensor-msgs-dev, "
                 "libtf2-msgs-dev): .bag input off")
endif()

# The node: roscpp, message_filters, cv_bridge and the message headers it publishes.
pkg_check_modules(ROSNODE QUIET IMPORTED_TARGET roscpp message_filters cv_bridge tf2_ros)
find_path(NAV_MSGS_INCLUDE_DIR nav_msgs/Odometry.h)
find_path(STD_SRVS_INCLUDE_DIR std_srvs/Trigger.h)
find_path(VIS_MSGS_INCLUDE_DIR visualization_msgs/MarkerArray.h)
if(ROSNODE_FOUND AND NAV_MSGS_INCLUDE_DIR AND STD_SRVS_INCLUDE_DIR AND VIS_MSGS_INCLUDE_DIR AND TF2_MSGS_INCLUDE_DIR)
  set(VARSLAM_HAVE_ROSNODE ON)
  message(STATUS "varslam: ROS 1 node on (varslam_node)")
else()
  message(STATUS "varslam: ROS node off (needs libroscpp-dev, libmessage-filters-dev, libcv-bridge-dev, "
                 "libnav-msgs-dev, libstd-srvs-dev, libvisualization-msgs-dev, libtf2-ros-dev)")
endif()
