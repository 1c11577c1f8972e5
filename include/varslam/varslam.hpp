#pragma once
// varslam's public API in one include (C++17): the session (varslam::Slam), its settings (varslam::Config), the
// value types it hands out, its errors, where its log goes, and ROS bags as input. Nothing of Ceres, glog, yaml-cpp,
// Eigen or the SLAM internals. docs/api.md has a complete example.
#include <varslam/bag.hpp>
#include <varslam/config.hpp>
#include <varslam/error.hpp>
#include <varslam/log.hpp>
#include <varslam/slam.hpp>
#include <varslam/types.hpp>
