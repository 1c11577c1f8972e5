#pragma once
// ROS 1 bag files read and written through the rosbag storage library, with no ROS type in this header and no ROS
// master needed. C++17 (ROS 1 message headers do not compile as C++20): the rest of varslam sees only these
// plain types.
#include <array>
#include <cstddef>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace varslam::bagfile {

struct Topic {
  std::string name;
  std::string type;  // e.g. "sensor_msgs/Image"
  std::size_t messages = 0;
};

/// A sensor_msgs/CameraInfo, as far as a pinhole camera needs it.
struct CameraInfo {
  std::string frame_id;
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::string distortion_model;  // "plumb_bob", "rational_polynomial", ... or empty
  std::vector<double> d;         // distortion coefficients as given
};

/// One transform of /tf or /tf_static: the pose of `child` in `parent`.
struct Transform {
  double stamp = 0;
  std::string parent, child;
  double tx = 0, ty = 0, tz = 0, qx = 0, qy = 0, qz = 0, qw = 1;
};

/// An image message decoded. Colour comes as CV_8UC3 BGR (mono8 as CV_8UC1); depth as CV_16UC1 raw units or
/// CV_32FC1 metres, as the message holds it.
struct Image {
  cv::Mat mat;
  std::string encoding;  // the message's encoding or compressed format, for messages
};

class Reader {
 public:
  /// Opens and indexes a bag. Throws varslam::InputError naming the file: missing, not a bag, unindexed (with how
  /// to reindex), or unreadable.
  explicit Reader(const std::string& file);
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  const std::string& file() const;
  std::vector<Topic> topics() const;
  /// Per message of the topic, in bag order: the header stamp (the bag's receive time where the header has none).
  std::vector<double> stamps(const std::string& topic) const;
  /// The i-th message of an image topic (sensor_msgs/Image or CompressedImage), decoded. Thread-safe. Throws
  /// varslam::InputError naming the topic and message on an unknown encoding or broken data.
  Image image(const std::string& topic, std::size_t i) const;
  /// The encoding (Image) or format (CompressedImage) of the first message of an image topic.
  std::string encoding(const std::string& topic) const;
  /// The first message of a sensor_msgs/CameraInfo topic.
  std::optional<CameraInfo> camera_info(const std::string& topic) const;
  /// The first value of a std_msgs/Float32 or Float64 topic (RealSense recordings store options this way).
  std::optional<double> number(const std::string& topic) const;
  /// Every transform in /tf and /tf_static whose child frame is `child` (leading '/' ignored), in bag order.
  std::vector<Transform> transforms(const std::string& child) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Writes a bag (what `varslam bag-from-folder` and the tests use). Messages are written in the order given.
class Writer {
 public:
  explicit Writer(const std::string& file);  // throws varslam::InputError when the file cannot be created
  ~Writer();                                 // closes
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  /// sensor_msgs/Image. `encoding`: rgb8, bgr8, mono8, mono16, 16UC1 or 32FC1, matching the matrix's type.
  void image(const std::string& topic, double stamp, const std::string& frame_id, const cv::Mat& mat,
             const std::string& encoding);
  /// sensor_msgs/CompressedImage. `format`: "jpeg" or "png" for a BGR image; "16UC1; compressedDepth png" for a
  /// CV_16UC1 depth image (PNG after the 12-byte compressedDepth header, as image_transport writes it).
  void compressed(const std::string& topic, double stamp, const std::string& frame_id, const cv::Mat& mat,
                  const std::string& format);
  void camera_info(const std::string& topic, double stamp, const CameraInfo& info);
  void transform(const std::string& topic, const Transform& t);  // one tf2_msgs/TFMessage
  /// geometry_msgs/PolygonStamped: the node's person-box input (two corners per box, z = score).
  void polygon(const std::string& topic, double stamp, const std::string& frame_id,
               const std::vector<std::array<float, 3>>& points);
  void float32(const std::string& topic, double stamp, float value);
  void uint32(const std::string& topic, double stamp, unsigned value);
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace varslam::bagfile
