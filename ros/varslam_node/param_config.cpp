#include "param_config.hpp"

#include <xmlrpcpp/XmlRpcValue.h>

#include <set>
#include <sstream>

namespace varslam_ros {
namespace {

const std::set<std::string> kNodeParams = {"settings_file", "map_frame",           "camera_frame",      "odom_frame",
                                           "map_file",      "load_map_at_start",   "localization_only", "realtime",
                                           "depth_unit",    "map_every_keyframes", "stats_file",        "viewer",
                                           "viewer_port",   "viewer_address",      "dense_map_rate",    "dense_map_cell"};

std::string as_text(XmlRpc::XmlRpcValue& v, const std::string& name) {
  std::ostringstream s;
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return static_cast<bool>(v) ? "true" : "false";
    case XmlRpc::XmlRpcValue::TypeInt:
      return std::to_string(static_cast<int>(v));
    case XmlRpc::XmlRpcValue::TypeDouble:
      s.precision(17);
      s << static_cast<double>(v);
      return s.str();
    case XmlRpc::XmlRpcValue::TypeString:
      return static_cast<std::string>(v);
    default:
      throw varslam::ConfigError("parameter " + name + ": a setting takes a number, a boolean or a string");
  }
}

}  // namespace

void apply_setting_params(const ros::NodeHandle& pnh, varslam::Config& config) {
  std::vector<std::string> names;
  ros::NodeHandle(pnh).getParamNames(names);
  const std::string prefix = pnh.getNamespace() + "/";
  for (const std::string& full : names) {
    if (full.rfind(prefix, 0) != 0) continue;
    const std::string local = full.substr(prefix.size());  // e.g. tracking/kernel
    if (kNodeParams.count(local)) continue;
    std::string key = local;
    for (char& c : key)
      if (c == '/') c = '.';
    XmlRpc::XmlRpcValue v;
    pnh.getParam(local, v);
    try {
      config.set(key, as_text(v, full));
    } catch (const varslam::ConfigError& e) {
      throw varslam::ConfigError("parameter " + full + ": " + e.what());
    }
  }
}

NodeParams read_params(const ros::NodeHandle& pnh, varslam::Config& config) {
  NodeParams p;
  pnh.param("settings_file", p.settings_file, p.settings_file);
  pnh.param("map_frame", p.map_frame, p.map_frame);
  pnh.param("camera_frame", p.camera_frame, p.camera_frame);
  pnh.param("odom_frame", p.odom_frame, p.odom_frame);
  pnh.param("map_file", p.map_file, p.map_file);
  pnh.param("load_map_at_start", p.load_map_at_start, p.load_map_at_start);
  pnh.param("localization_only", p.localization_only, p.localization_only);
  pnh.param("realtime", p.realtime, p.realtime);
  pnh.param("depth_unit", p.depth_unit, p.depth_unit);
  pnh.param("map_every_keyframes", p.map_every_keyframes, p.map_every_keyframes);
  pnh.param("stats_file", p.stats_file, p.stats_file);
  pnh.param("viewer", p.viewer, p.viewer);
  pnh.param("viewer_port", p.viewer_port, p.viewer_port);
  pnh.param("viewer_address", p.viewer_address, p.viewer_address);
  pnh.param("dense_map_rate", p.dense_map_rate, p.dense_map_rate);
  pnh.param("dense_map_cell", p.dense_map_cell, p.dense_map_cell);
  if (!(p.dense_map_rate > 0 && p.dense_map_rate <= 30))
    throw varslam::ConfigError("parameter ~dense_map_rate: " + std::to_string(p.dense_map_rate) +
                               " clouds per second is not in (0, 30]");
  if (p.dense_map_cell != 1 && p.dense_map_cell != 2 && p.dense_map_cell != 4 && p.dense_map_cell != 8)
    throw varslam::ConfigError("parameter ~dense_map_cell: " + std::to_string(p.dense_map_cell) +
                               " voxels is not 1, 2, 4 or 8");
  if (p.viewer_port < 0 || p.viewer_port > 65535)
    throw varslam::ConfigError("parameter ~viewer_port: " + std::to_string(p.viewer_port) + " is not a port (0-65535)");
  if (!(p.depth_unit > 0 && p.depth_unit < 1))
    throw varslam::ConfigError("parameter ~depth_unit: " + std::to_string(p.depth_unit) +
                               " metres per depth step is not in (0, 1)");
  if (p.map_every_keyframes < 1) throw varslam::ConfigError("parameter ~map_every_keyframes: must be 1 or more");
  if ((p.load_map_at_start || p.localization_only) && p.map_file.empty())
    throw varslam::ConfigError("parameter ~load_map_at_start / ~localization_only: needs ~map_file");
  if (!p.settings_file.empty()) config = varslam::Config::from_file(p.settings_file);
  apply_setting_params(pnh, config);
  return p;
}

}  // namespace varslam_ros
