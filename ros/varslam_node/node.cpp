#include "node.hpp"

#include <cv_bridge/cv_bridge.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <std_msgs/Float64.h>
#include <std_msgs/String.h>
#include <tf2/LinearMath/Transform.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <boost/bind/bind.hpp>
#include <cstdio>
#include <fstream>
#include <future>
#include <opencv2/imgproc.hpp>

namespace varslam_ros {
namespace {

namespace enc = sensor_msgs::image_encodings;

geometry_msgs::Pose to_msg(const varslam::Pose& p) {
  geometry_msgs::Pose m;
  m.position.x = p.translation[0];
  m.position.y = p.translation[1];
  m.position.z = p.translation[2];
  m.orientation.x = p.rotation[0];
  m.orientation.y = p.rotation[1];
  m.orientation.z = p.rotation[2];
  m.orientation.w = p.rotation[3];
  return m;
}

const char* state_name(varslam::TrackingState s) {
  switch (s) {
    case varslam::TrackingState::Tracking:
      return "tracking";
    case varslam::TrackingState::Lost:
      return "lost";
    case varslam::TrackingState::NotInitialized:
      return "not_initialized";
  }
  return "unknown";
}

double percentile(const std::deque<double>& window, double q) {
  if (window.empty()) return 0;
  std::vector<double> v(window.begin(), window.end());
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

// Depth as the session takes it: CV_32FC1 metres, 0 where there is none.
cv::Mat depth_metres(const sensor_msgs::ImageConstPtr& msg, double depth_unit) {
  const cv_bridge::CvImageConstPtr d = cv_bridge::toCvShare(msg);
  cv::Mat m;
  if (msg->encoding == enc::TYPE_16UC1 || msg->encoding == enc::MONO16) {
    d->image.convertTo(m, CV_32FC1, depth_unit);
  } else if (msg->encoding == enc::TYPE_32FC1) {
    m = d->image.clone();
    cv::patchNaNs(m, 0.0);
    cv::max(m, 0.0, m);
  } else {
    throw varslam::InputError("depth image of encoding '" + msg->encoding + "': expected 16UC1, mono16 or 32FC1");
  }
  return m;
}

}  // namespace

VarslamNode::VarslamNode(ros::NodeHandle nh, ros::NodeHandle pnh) : nh_(nh), pnh_(pnh) {
  params_ = read_params(pnh_, config_);
  have_camera_ = !params_.settings_file.empty();
  odom_pub_ = pnh_.advertise<nav_msgs::Odometry>("odometry", 100);
  tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf", 100);
  path_pub_ = pnh_.advertise<nav_msgs::Path>("path", 1);
  corrected_path_pub_ = pnh_.advertise<nav_msgs::Path>("corrected_path", 1, true);
  points_pub_ = pnh_.advertise<sensor_msgs::PointCloud2>("map_points", 1, true);
  keyframes_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("keyframes", 1, true);
  state_pub_ = pnh_.advertise<std_msgs::String>("state", 10);
  alpha_pub_ = pnh_.advertise<std_msgs::Float64>("local_ba_alpha", 10);
  people_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("person_boxes", 10);
  const bool dense = config_.get("dense.enabled") == "true";
  if (dense) dense_pub_ = pnh_.advertise<sensor_msgs::PointCloud2>("dense_map", 1, true);
  people_sub_ = nh_.subscribe("people", 100, &VarslamNode::on_people, this);
  initial_pose_sub_ = nh_.subscribe("initialpose", 1, &VarslamNode::on_initial_pose, this);
  save_srv_ = pnh_.advertiseService("save_map", &VarslamNode::save_map, this);
  load_srv_ = pnh_.advertiseService("load_map", &VarslamNode::load_map, this);
  reset_srv_ = pnh_.advertiseService("reset", &VarslamNode::reset, this);
  loc_srv_ = pnh_.advertiseService("localization_only", &VarslamNode::localization_only, this);
  // Deep subscriber queues: a frame waits rather than being dropped while the tracking thread is busy.
  rgb_sub_.subscribe(nh_, "rgb/image", 100);
  depth_sub_.subscribe(nh_, "depth/image", 100);
  sync_ = std::make_unique<message_filters::Synchronizer<SyncPolicy>>(SyncPolicy(100), rgb_sub_, depth_sub_);
  sync_->registerCallback(boost::bind(&VarslamNode::on_images, this, boost::placeholders::_1, boost::placeholders::_2));
  colour_count_sub_ = nh_.subscribe("rgb/image", 100, &VarslamNode::on_colour_seen, this);
  if (!have_camera_) info_sub_ = nh_.subscribe("rgb/camera_info", 10, &VarslamNode::on_camera_info, this);
  if (!params_.odom_frame.empty()) {
    tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh_);
  }
  tracker_ = std::thread([this] { tracking_loop(); });
  if (dense) dense_thread_ = std::thread([this] { dense_loop(); });
  ROS_INFO("varslam %s: colour %s, depth %s, camera %s; %s mode", varslam::Slam::version().c_str(),
           rgb_sub_.getTopic().c_str(), depth_sub_.getTopic().c_str(),
           have_camera_ ? params_.settings_file.c_str() : nh_.resolveName("rgb/camera_info").c_str(),
           params_.realtime ? "real-time" : "deterministic");
}

VarslamNode::~VarslamNode() {
  {
    std::lock_guard<std::mutex> lock(dense_mutex_);
    dense_stop_ = true;
  }
  dense_cv_.notify_all();
  if (dense_thread_.joinable()) dense_thread_.join();
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    stop_ = true;
  }
  queue_cv_.notify_all();
  tracker_.join();
  if (slam_) {
    slam_->finish();
    publish_corrected_path(ros::Time::now());
  }
  write_stats();
}

void VarslamNode::on_camera_info(const sensor_msgs::CameraInfoConstPtr& info) {
  std::lock_guard<std::mutex> lock(queue_mutex_);
  if (have_camera_) return;
  try {
    config_.set("camera.fx", info->K[0]).set("camera.fy", info->K[4]).set("camera.cx", info->K[2]);
    config_.set("camera.cy", info->K[5]).set("camera.width", info->width).set("camera.height", info->height);
    const char* keys[] = {"camera.k1", "camera.k2", "camera.p1", "camera.p2", "camera.k3"};
    for (std::size_t k = 0; k < 5 && k < info->D.size(); ++k) config_.set(keys[k], info->D[k]);
    apply_setting_params(pnh_, config_);  // parameters win over CameraInfo
  } catch (const varslam::InputError& e) {
    ROS_FATAL("CameraInfo on %s: %s", info_sub_.getTopic().c_str(), e.what());
    ros::shutdown();
    return;
  }
  have_camera_ = true;
  ROS_INFO("camera from CameraInfo %s: fx %.3f fy %.3f cx %.3f cy %.3f, %ux%u", info_sub_.getTopic().c_str(),
           info->K[0], info->K[4], info->K[2], info->K[5], info->width, info->height);
  queue_cv_.notify_all();
}

void VarslamNode::on_people(const geometry_msgs::PolygonStampedConstPtr& msg) {
  std::vector<varslam::PersonBox> boxes;
  const auto& pts = msg->polygon.points;
  for (std::size_t i = 0; i + 1 < pts.size(); i += 2)
    boxes.push_back({pts[i].x, pts[i].y, pts[i + 1].x - pts[i].x, pts[i + 1].y - pts[i].y, pts[i].z});
  {
    std::lock_guard<std::mutex> lock(people_mutex_);
    people_[msg->header.stamp] = std::move(boxes);
  }
  people_cv_.notify_all();
}

std::optional<std::vector<varslam::PersonBox>> VarslamNode::people_for(const ros::Time& stamp) {
  std::unique_lock<std::mutex> lock(people_mutex_);
  // Boxes travel on their own topic: give them a moment when someone publishes them.
  if (people_sub_.getNumPublishers() > 0)
    people_cv_.wait_for(lock, std::chrono::milliseconds(20), [&] { return people_.count(stamp) > 0; });
  std::optional<std::vector<varslam::PersonBox>> out;
  if (const auto it = people_.find(stamp); it != people_.end()) out = it->second;
  people_.erase(people_.begin(), people_.upper_bound(stamp));  // older stamps will not be asked for again
  return out;
}

void VarslamNode::on_person_boxes(const varslam::PersonBoxesInfo& info) {
  if (people_pub_.getNumSubscribers() == 0) return;
  // Each box drawn as a rectangle 1 m in front of the camera (the image plane at unit depth), in the camera frame.
  const auto [fx, fy, cx, cy] = intrinsics_;
  visualization_msgs::MarkerArray markers;
  visualization_msgs::Marker m;
  m.header.stamp = ros::Time(info.timestamp);
  m.header.frame_id = params_.camera_frame;
  m.ns = "person_boxes";
  m.type = visualization_msgs::Marker::LINE_LIST;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1;
  m.scale.x = 0.005;
  m.color.r = 1.0f, m.color.g = 0.3f, m.color.a = 1.0f;
  m.lifetime = ros::Duration(0.5);
  auto corner = [&](double u, double v) {
    geometry_msgs::Point p;
    p.x = (u - cx) / fx, p.y = (v - cy) / fy, p.z = 1.0;
    return p;
  };
  for (const auto& b : info.boxes) {
    const geometry_msgs::Point a = corner(b.x, b.y), c = corner(b.x + b.width, b.y + b.height);
    const geometry_msgs::Point bb = corner(b.x + b.width, b.y), d = corner(b.x, b.y + b.height);
    for (const auto& [p, q] : {std::pair{a, bb}, std::pair{bb, c}, std::pair{c, d}, std::pair{d, a}}) {
      m.points.push_back(p);
      m.points.push_back(q);
    }
  }
  markers.markers.push_back(m);
  people_pub_.publish(markers);
}

void VarslamNode::on_images(const sensor_msgs::ImageConstPtr& rgb, const sensor_msgs::ImageConstPtr& depth) {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    queue_.push_back({rgb, depth, Clock::now()});
    ++stats_.synced;
    stats_.max_queue = std::max(stats_.max_queue, queue_.size());
  }
  queue_cv_.notify_one();
}

void VarslamNode::tracking_loop() {
  for (;;) {
    Pending p;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_cv_.wait(lock, [&] { return stop_ || (!queue_.empty() && have_camera_); });
      if (queue_.empty() || !have_camera_) return;  // stopping
      p = std::move(queue_.front());
      queue_.pop_front();
    }
    while (services_waiting_.load() > 0) std::this_thread::yield();
    std::lock_guard<std::mutex> session(session_mutex_);
    track(p);
  }
}

void VarslamNode::ensure_session(const sensor_msgs::Image& rgb) {
  if (slam_) return;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    slam_ = std::make_unique<varslam::Slam>(config_,
                                            params_.realtime ? varslam::Mode::RealTime : varslam::Mode::Deterministic);
  }
  slam_->add_listener(*this);
  session_ = slam_.get();
  // Read once: the camera does not change within a session (it is drawn with on every frame's person boxes).
  intrinsics_ = {std::stod(config_.get("camera.fx")), std::stod(config_.get("camera.fy")),
                 std::stod(config_.get("camera.cx")), std::stod(config_.get("camera.cy"))};
  if (params_.viewer) {
    varslam::ViewerOptions v;
    v.port = params_.viewer_port;
    v.address = params_.viewer_address;
    v.title = ros::this_node::getName();
    try {
      ROS_INFO("viewer: open %s in a browser", slam_->start_viewer(v).c_str());
    } catch (const varslam::InputError& e) {
      ROS_ERROR("viewer not started: %s", e.what());
    }
  }
  if (params_.camera_frame.empty()) params_.camera_frame = rgb.header.frame_id.empty() ? "camera" : rgb.header.frame_id;
  if (params_.camera_frame.front() == '/') params_.camera_frame.erase(0, 1);  // tf2 frame ids have no leading '/'
  if (params_.load_map_at_start) slam_->load_map(params_.map_file);
  if (params_.localization_only) slam_->set_localization_only(true);
  if (pending_hint_) slam_->relocalize_near(pending_hint_->first, pending_hint_->second);
  pending_hint_.reset();
}

void VarslamNode::track(const Pending& p) {
  try {
    ensure_session(*p.rgb);
    const cv_bridge::CvImageConstPtr colour = cv_bridge::toCvShare(p.rgb, enc::BGR8);
    const cv::Mat depth = depth_metres(p.depth, params_.depth_unit);
    const auto people = people_for(p.rgb->header.stamp);
    const double t = p.rgb->header.stamp.toSec();
    const varslam::TrackedFrame f =
        people ? slam_->track(colour->image, depth, t, *people) : slam_->track(colour->image, depth, t);
    if (people) ++stats_.with_people;
    publish_pose(f, p.rgb->header);
    stats_.latency_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - p.received).count());
    if (stats_.latency_ms.size() > Stats::kLatencyWindow) stats_.latency_ms.pop_front();
    if (f.pose)
      ++stats_.tracked;
    else
      ++stats_.lost;
    if (f.keyframe && ++keyframes_since_map_ >= static_cast<std::size_t>(params_.map_every_keyframes)) {
      keyframes_since_map_ = 0;
      publish_map(p.rgb->header.stamp);
      publish_corrected_path(p.rgb->header.stamp);
    }
  } catch (const varslam::InputError& e) {
    ++stats_.rejected;
    ROS_WARN_THROTTLE(2.0, "frame at %.6f not used: %s", p.rgb->header.stamp.toSec(), e.what());
  } catch (const cv_bridge::Exception& e) {
    ++stats_.rejected;
    ROS_WARN_THROTTLE(2.0, "frame at %.6f not used: %s", p.rgb->header.stamp.toSec(), e.what());
  }
}

void VarslamNode::publish_pose(const varslam::TrackedFrame& f, const std_msgs::Header& header) {
  std_msgs::String state;
  state.data = state_name(f.state);
  state_pub_.publish(state);
  if (!f.pose) return;
  nav_msgs::Odometry odom;
  odom.header.stamp = header.stamp;
  odom.header.frame_id = params_.map_frame;
  odom.child_frame_id = params_.camera_frame;
  odom.pose.pose = to_msg(*f.pose);
  odom_pub_.publish(odom);
  if (const auto t = map_transform(odom)) {
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(*t);
    tf_pub_.publish(tf);
  }
  geometry_msgs::PoseStamped ps;
  ps.header = odom.header;
  ps.pose = odom.pose.pose;
  live_path_.header = odom.header;
  live_path_.poses.push_back(ps);
  if (path_pub_.getNumSubscribers() > 0) path_pub_.publish(live_path_);
}

std::optional<geometry_msgs::TransformStamped> VarslamNode::map_transform(const nav_msgs::Odometry& odom) const {
  const auto& p = odom.pose.pose;
  const tf2::Transform map_camera(tf2::Quaternion(p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w),
                                  tf2::Vector3(p.position.x, p.position.y, p.position.z));
  tf2::Transform out = map_camera;
  geometry_msgs::TransformStamped t;
  t.header = odom.header;
  t.child_frame_id = params_.camera_frame;
  if (tf_buffer_) {  // map -> odom = (map -> camera) * (odom -> camera)^-1
    try {
      const auto oc =
          tf_buffer_->lookupTransform(params_.odom_frame, params_.camera_frame, odom.header.stamp, ros::Duration(0.05));
      const auto& r = oc.transform.rotation;
      const auto& x = oc.transform.translation;
      out = map_camera * tf2::Transform(tf2::Quaternion(r.x, r.y, r.z, r.w), tf2::Vector3(x.x, x.y, x.z)).inverse();
      t.child_frame_id = params_.odom_frame;
    } catch (const tf2::TransformException& e) {
      ROS_WARN_THROTTLE(2.0, "no %s -> %s on /tf at %.3f: map -> %s not published (%s)", params_.odom_frame.c_str(),
                        params_.camera_frame.c_str(), odom.header.stamp.toSec(), params_.odom_frame.c_str(), e.what());
      return std::nullopt;
    }
  }
  t.transform.translation.x = out.getOrigin().x();
  t.transform.translation.y = out.getOrigin().y();
  t.transform.translation.z = out.getOrigin().z();
  const tf2::Quaternion q = out.getRotation();
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  return t;
}

void VarslamNode::publish_map(const ros::Time& stamp) {
  const std::shared_ptr<const varslam::MapSnapshot> map = slam_->map_snapshot();
  sensor_msgs::PointCloud2 cloud;
  cloud.header.stamp = stamp;
  cloud.header.frame_id = params_.map_frame;
  sensor_msgs::PointCloud2Modifier mod(cloud);
  mod.setPointCloud2FieldsByString(1, "xyz");
  mod.resize(map->points.size());
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
  for (const auto& p : map->points) {
    *x = static_cast<float>(p.position[0]);
    *y = static_cast<float>(p.position[1]);
    *z = static_cast<float>(p.position[2]);
    ++x, ++y, ++z;
  }
  points_pub_.publish(cloud);
  visualization_msgs::MarkerArray markers;
  visualization_msgs::Marker m;
  m.header = cloud.header;
  m.ns = "keyframes";
  m.id = 0;
  m.type = visualization_msgs::Marker::SPHERE_LIST;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1;
  m.scale.x = m.scale.y = m.scale.z = 0.03;
  m.color.r = 0.2f, m.color.g = 0.6f, m.color.b = 1.0f, m.color.a = 1.0f;
  for (const auto& kf : map->keyframes) {
    geometry_msgs::Point pt;
    pt.x = kf.pose.translation[0], pt.y = kf.pose.translation[1], pt.z = kf.pose.translation[2];
    m.points.push_back(pt);
  }
  markers.markers.push_back(m);
  keyframes_pub_.publish(markers);
}

void VarslamNode::dense_loop() {
  const auto period = std::chrono::duration<double>(1.0 / params_.dense_map_rate);
  std::unique_lock<std::mutex> lock(dense_mutex_);
  for (;;) {
    if (dense_cv_.wait_for(lock, period, [&] { return dense_stop_; })) return;
    const varslam::Slam* slam = session_.load();
    if (!slam || dense_pub_.getNumSubscribers() == 0) continue;
    lock.unlock();
    try {
      publish_dense(*slam);
    } catch (const varslam::InputError& e) {
      ROS_WARN_THROTTLE(10.0, "dense map not published: %s", e.what());
    }
    lock.lock();
  }
}

void VarslamNode::publish_dense(const varslam::Slam& slam) {
  varslam::DenseMapRequest request;
  request.mesh = request.occupancy = false;
  request.surface = true;
  request.surface_cell_voxels = params_.dense_map_cell;
  // Reads only what changed since the last cloud, a few blocks at a time: tracking goes on meanwhile.
  const std::shared_ptr<const varslam::DenseMapSnapshot> map = slam.dense_map_snapshot(request);
  sensor_msgs::PointCloud2 cloud;
  cloud.header.stamp = ros::Time::now();
  cloud.header.frame_id = params_.map_frame;
  sensor_msgs::PointCloud2Modifier mod(cloud);
  mod.setPointCloud2FieldsByString(2, "xyz", "rgb");
  mod.resize(map->surface.size());
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
  sensor_msgs::PointCloud2Iterator<std::uint8_t> r(cloud, "r"), g(cloud, "g"), b(cloud, "b");
  for (std::size_t i = 0; i < map->surface.size(); ++i, ++x, ++y, ++z, ++r, ++g, ++b) {
    *x = map->surface[i][0], *y = map->surface[i][1], *z = map->surface[i][2];
    *r = map->surface_colours[i][0], *g = map->surface_colours[i][1], *b = map->surface_colours[i][2];
  }
  dense_pub_.publish(cloud);
}

void VarslamNode::publish_corrected_path(const ros::Time& stamp) {
  nav_msgs::Path path;
  path.header.stamp = stamp;
  path.header.frame_id = params_.map_frame;
  for (const varslam::TimedPose& p : slam_->camera_trajectory()) {
    geometry_msgs::PoseStamped ps;
    ps.header.stamp = ros::Time(p.timestamp);
    ps.header.frame_id = params_.map_frame;
    ps.pose = to_msg(p.pose);
    path.poses.push_back(ps);
  }
  corrected_path_pub_.publish(path);
}

void VarslamNode::on_local_ba(const varslam::LocalBaInfo& info) {
  std_msgs::Float64 a;
  a.data = info.alpha;
  alpha_pub_.publish(a);
}

// Services run between frames: they hold the session lock the tracking thread holds for each frame.
std::unique_lock<std::mutex> VarslamNode::lock_for_service() {
  ++services_waiting_;
  std::unique_lock<std::mutex> lock(session_mutex_);
  --services_waiting_;
  return lock;
}

bool VarslamNode::save_map(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  const auto lock = lock_for_service();
  if (params_.map_file.empty()) {
    res.success = false;
    res.message = "no ~map_file parameter: where to save the map";
    return true;
  }
  try {
    if (!slam_) throw varslam::InputError("no map yet: no frame was tracked");
    slam_->save_map(params_.map_file);  // thread-safe: waits for the current frame
    res.success = true;
    res.message = "map saved to " + params_.map_file;
  } catch (const varslam::InputError& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

bool VarslamNode::load_map(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  if (params_.map_file.empty()) {
    res.success = false;
    res.message = "no ~map_file parameter: which map to load";
    return true;
  }
  const auto lock = lock_for_service();
  try {
    if (!slam_) {
      params_.load_map_at_start = true;
      res.message = "the map will be loaded with the first frame: " + params_.map_file;
    } else {
      slam_->load_map(params_.map_file);
      live_path_.poses.clear();
      res.message = "map loaded from " + params_.map_file + "; relocalizing in it";
    }
    res.success = true;
  } catch (const varslam::InputError& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

bool VarslamNode::reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  const auto lock = lock_for_service();
  if (slam_) slam_->reset();
  live_path_.poses.clear();
  res.success = true;
  res.message = "session reset";
  return true;
}

void VarslamNode::on_initial_pose(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg) {
  const std::string& frame = msg->header.frame_id;
  if (!frame.empty() && frame != params_.map_frame && frame != "/" + params_.map_frame) {
    ROS_WARN("initialpose in frame '%s' ignored: give the camera's pose in ~map_frame '%s'", frame.c_str(),
             params_.map_frame.c_str());
    return;
  }
  const auto& p = msg->pose.pose;
  varslam::Pose pose;
  pose.translation = {p.position.x, p.position.y, p.position.z};
  pose.rotation = {p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w};
  // Three standard deviations of the position, at least 0.3 m; RViz's 2D Pose Estimate gives 0.5 m in x and y.
  const auto& c = msg->pose.covariance;
  const double radius = std::max(0.3, 3 * std::sqrt(std::max({c[0], c[7], c[14], 0.0})));
  const auto lock = lock_for_service();
  try {
    if (slam_) slam_->relocalize_near(pose, radius);
    else pending_hint_ = std::make_pair(pose, radius);
    ROS_INFO("relocalization hint: (%.2f, %.2f, %.2f) in %s, within %.2f m, used while tracking is lost", p.position.x,
             p.position.y, p.position.z, params_.map_frame.c_str(), radius);
  } catch (const varslam::InputError& e) {
    ROS_WARN("initialpose ignored: %s", e.what());
  }
}

bool VarslamNode::localization_only(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
  const auto lock = lock_for_service();
  try {
    if (!slam_) throw varslam::InputError("no session yet: no frame was tracked");
    slam_->set_localization_only(req.data);
    params_.localization_only = req.data;
    res.success = true;
    res.message = req.data ? "localization only: the map is not extended" : "mapping";
  } catch (const varslam::InputError& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

void VarslamNode::write_stats() const {
  if (params_.stats_file.empty()) return;
  std::ofstream out(params_.stats_file);
  out << "{\"colour_messages\": " << colour_seen_.load() << ", \"synced_pairs\": " << stats_.synced
      << ", \"tracked\": " << stats_.tracked << ", \"lost\": " << stats_.lost << ", \"rejected\": " << stats_.rejected
      << ", \"max_queue\": " << stats_.max_queue << ", \"frames_with_person_boxes\": " << stats_.with_people
      << ", \"latency_ms_median\": " << percentile(stats_.latency_ms, 0.5)
      << ", \"latency_ms_p95\": " << percentile(stats_.latency_ms, 0.95) << "}\n";
}

}  // namespace varslam_ros
