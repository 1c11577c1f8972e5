#include "bagfile/bag_file.hpp"

#include <geometry_msgs/PolygonStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Float32.h>
#include <std_msgs/Float64.h>
#include <std_msgs/UInt32.h>
#include <tf2_msgs/TFMessage.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.hpp"
#include "io/ros_image_codec.hpp"

namespace varslam::bagfile {
namespace {

constexpr char kImageType[] = "sensor_msgs/Image";
constexpr char kCompressedType[] = "sensor_msgs/CompressedImage";

std::string strip_slash(const std::string& s) { return !s.empty() && s[0] == '/' ? s.substr(1) : s; }

// What the first bytes say, before rosbag's own less specific errors.
void check_is_bag(const std::string& file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(file + ": bag file does not exist");
  if (!fs::is_regular_file(file, ec)) throw InputError(file + ": not a file (a bag is one .bag file)");
  std::ifstream in(file, std::ios::binary);
  char head[13] = {};
  in.read(head, 13);
  if (in.gcount() < 13 || std::memcmp(head, "#ROSBAG V", 9) != 0)
    throw InputError(file + ": not a ROS bag (no '#ROSBAG V2.0' header)");
  if (std::memcmp(head, "#ROSBAG V2.0", 12) != 0)
    throw InputError(file + ": ROS bag of format " + std::string(head + 9, 3) + "; only version 2.0 is read");
}

}  // namespace

struct Reader::Impl {
  std::string file;
  rosbag::Bag bag;
  std::unique_ptr<rosbag::View> view;
  std::map<std::string, std::vector<rosbag::MessageInstance>> messages;  // per topic, in bag order
  std::map<std::string, std::string> types;
  mutable std::mutex mutex;  // rosbag reads through one file handle

  const std::vector<rosbag::MessageInstance>& topic(const std::string& name) const {
    const auto it = messages.find(name);
    if (it == messages.end()) throw InputError(file + ": no topic " + name);
    return it->second;
  }

  template <typename Msg>
  boost::shared_ptr<Msg> read(const rosbag::MessageInstance& m, const std::string& where) const {
    std::lock_guard<std::mutex> lock(mutex);
    try {
      return m.instantiate<Msg>();
    } catch (const std::exception& e) {
      throw InputError(where + ": cannot read the message (" + e.what() + "); the bag may be truncated");
    }
  }
};

Reader::Reader(const std::string& file) : impl_(std::make_unique<Impl>()) {
  impl_->file = file;
  check_is_bag(file);
  const std::string repair = "; rebuild its index with `rosbag reindex " + file +
                             "` (package python3-rosbag; it keeps the original as .orig.bag) and try again";
  try {
    impl_->bag.open(file, rosbag::bagmode::Read);
  } catch (const rosbag::BagUnindexedException&) {
    throw InputError(file + ": the bag is not indexed (its recording was cut off?)" + repair);
  } catch (const std::exception& e) {
    throw InputError(file + ": the bag is truncated or not indexed (" + e.what() + ")" + repair);
  }
  try {
    impl_->view = std::make_unique<rosbag::View>(impl_->bag);
    for (const rosbag::MessageInstance& m : *impl_->view) {
      impl_->messages[m.getTopic()].push_back(m);
      impl_->types.emplace(m.getTopic(), m.getDataType());
    }
  } catch (const std::exception& e) {
    throw InputError(file + ": cannot read the bag's index: " + e.what());
  }
}

Reader::~Reader() = default;

const std::string& Reader::file() const { return impl_->file; }

std::vector<Topic> Reader::topics() const {
  std::vector<Topic> out;
  for (const auto& [name, msgs] : impl_->messages) out.push_back({name, impl_->types.at(name), msgs.size()});
  return out;
}

std::vector<double> Reader::stamps(const std::string& topic) const {
  const auto& msgs = impl_->topic(topic);
  const std::string& type = impl_->types.at(topic);
  std::vector<double> out;
  out.reserve(msgs.size());
  for (std::size_t i = 0; i < msgs.size(); ++i) {
    const std::string where = impl_->file + ":" + topic + "#" + std::to_string(i);
    ros::Time t;
    if (type == kImageType) {
      if (auto p = impl_->read<sensor_msgs::Image>(msgs[i], where)) t = p->header.stamp;
    } else if (type == kCompressedType) {
      if (auto p = impl_->read<sensor_msgs::CompressedImage>(msgs[i], where)) t = p->header.stamp;
    }
    out.push_back(t.isZero() ? msgs[i].getTime().toSec() : t.toSec());
  }
  return out;
}

std::string Reader::encoding(const std::string& topic) const {
  const auto& msgs = impl_->topic(topic);
  if (msgs.empty()) return {};
  const std::string where = impl_->file + ":" + topic + "#0";
  const std::string& type = impl_->types.at(topic);
  if (type == kImageType) {
    if (auto p = impl_->read<sensor_msgs::Image>(msgs[0], where)) return p->encoding;
  } else if (type == kCompressedType) {
    if (auto p = impl_->read<sensor_msgs::CompressedImage>(msgs[0], where)) return p->format;
  }
  return {};
}

Image Reader::image(const std::string& topic, std::size_t i) const {
  const auto& msgs = impl_->topic(topic);
  const std::string where = impl_->file + ":" + topic + " message " + std::to_string(i);
  if (i >= msgs.size()) throw InputError(where + ": the topic has only " + std::to_string(msgs.size()) + " messages");
  const std::string& type = impl_->types.at(topic);
  if (type == kImageType) {
    const auto p = impl_->read<sensor_msgs::Image>(msgs[i], where);
    if (!p) throw InputError(where + ": not a " + std::string(kImageType));
    return {ros_image::decode_raw_image(p->encoding, p->width, p->height, p->step, p->is_bigendian != 0, p->data.data(),
                                        p->data.size(), where),
            p->encoding};
  }
  if (type == kCompressedType) {
    const auto p = impl_->read<sensor_msgs::CompressedImage>(msgs[i], where);
    if (!p) throw InputError(where + ": not a " + std::string(kCompressedType));
    return {ros_image::decode_compressed_image(p->format, p->data.data(), p->data.size(), where), p->format};
  }
  throw InputError(where + ": topic of type " + type + " is not an image (sensor_msgs/Image or CompressedImage)");
}

std::optional<CameraInfo> Reader::camera_info(const std::string& topic) const {
  const auto& msgs = impl_->topic(topic);
  if (msgs.empty()) return std::nullopt;
  const auto p = impl_->read<sensor_msgs::CameraInfo>(msgs[0], impl_->file + ":" + topic);
  if (!p) return std::nullopt;
  CameraInfo c;
  c.frame_id = p->header.frame_id;
  c.width = static_cast<int>(p->width);
  c.height = static_cast<int>(p->height);
  c.fx = p->K[0];
  c.fy = p->K[4];
  c.cx = p->K[2];
  c.cy = p->K[5];
  c.distortion_model = p->distortion_model;
  c.d = p->D;
  return c;
}

std::optional<double> Reader::number(const std::string& topic) const {
  const auto it = impl_->messages.find(topic);
  if (it == impl_->messages.end() || it->second.empty()) return std::nullopt;
  const std::string where = impl_->file + ":" + topic;
  if (auto f = impl_->read<std_msgs::Float32>(it->second[0], where)) return f->data;
  if (auto d = impl_->read<std_msgs::Float64>(it->second[0], where)) return d->data;
  return std::nullopt;
}

std::vector<Transform> Reader::transforms(const std::string& child) const {
  std::vector<Transform> out;
  const std::string want = strip_slash(child);
  for (const char* topic : {"/tf", "/tf_static"}) {
    const auto it = impl_->messages.find(topic);
    if (it == impl_->messages.end()) continue;
    for (std::size_t i = 0; i < it->second.size(); ++i) {
      const auto p =
          impl_->read<tf2_msgs::TFMessage>(it->second[i], impl_->file + ":" + topic + "#" + std::to_string(i));
      if (!p) continue;
      for (const auto& t : p->transforms) {
        if (strip_slash(t.child_frame_id) != want) continue;
        const auto& tr = t.transform.translation;
        const auto& q = t.transform.rotation;
        out.push_back(
            {t.header.stamp.toSec(), t.header.frame_id, t.child_frame_id, tr.x, tr.y, tr.z, q.x, q.y, q.z, q.w});
      }
    }
  }
  return out;
}

struct Writer::Impl {
  rosbag::Bag bag;
  std::string file;
  bool open = false;

  static std_msgs::Header header(double stamp, const std::string& frame_id) {
    std_msgs::Header h;
    h.stamp = ros::Time(stamp);
    h.frame_id = frame_id;
    return h;
  }
};

Writer::Writer(const std::string& file) : impl_(std::make_unique<Impl>()) {
  impl_->file = file;
  try {
    impl_->bag.open(file, rosbag::bagmode::Write);
    impl_->open = true;
  } catch (const std::exception& e) {
    throw InputError(file + ": cannot create the bag: " + e.what());
  }
}

Writer::~Writer() {
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() reports errors to callers that call it
  }
}

void Writer::close() {
  if (!impl_->open) return;
  impl_->open = false;
  impl_->bag.close();
}

void Writer::image(const std::string& topic, double stamp, const std::string& frame_id, const cv::Mat& mat,
                   const std::string& encoding) {
  const int bpp = ros_image::raw_bytes_per_pixel(encoding);
  if (bpp == 0 || static_cast<std::size_t>(bpp) != mat.elemSize())
    throw InputError("bag writer: encoding " + encoding + " does not match a matrix of " +
                     std::to_string(mat.elemSize()) + " bytes per pixel");
  cv::Mat data = mat;
  if (encoding == "rgb8") cv::cvtColor(mat, data, cv::COLOR_BGR2RGB);
  if (!data.isContinuous()) data = data.clone();
  sensor_msgs::Image m;
  m.header = Impl::header(stamp, frame_id);
  m.width = static_cast<std::uint32_t>(data.cols);
  m.height = static_cast<std::uint32_t>(data.rows);
  m.encoding = encoding;
  m.is_bigendian = 0;
  m.step = static_cast<std::uint32_t>(data.cols * bpp);
  m.data.assign(data.data, data.data + data.total() * data.elemSize());
  impl_->bag.write(topic, m.header.stamp, m);
}

void Writer::compressed(const std::string& topic, double stamp, const std::string& frame_id, const cv::Mat& mat,
                        const std::string& format) {
  sensor_msgs::CompressedImage m;
  m.header = Impl::header(stamp, frame_id);
  m.format = format;
  if (ros_image::is_compressed_depth(format)) {
    m.data = ros_image::encode_compressed_depth(mat);
  } else {
    std::vector<std::uint8_t> buf;
    const std::string ext = format.find("png") != std::string::npos ? ".png" : ".jpg";
    cv::imencode(ext, mat, buf);
    m.data = std::move(buf);
  }
  impl_->bag.write(topic, m.header.stamp, m);
}

void Writer::camera_info(const std::string& topic, double stamp, const CameraInfo& info) {
  sensor_msgs::CameraInfo m;
  m.header = Impl::header(stamp, info.frame_id);
  m.width = static_cast<std::uint32_t>(info.width);
  m.height = static_cast<std::uint32_t>(info.height);
  m.distortion_model = info.distortion_model.empty() ? "plumb_bob" : info.distortion_model;
  m.D = info.d.empty() ? std::vector<double>(5, 0.0) : info.d;
  m.K = {info.fx, 0, info.cx, 0, info.fy, info.cy, 0, 0, 1};
  m.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.P = {info.fx, 0, info.cx, 0, 0, info.fy, info.cy, 0, 0, 0, 1, 0};
  impl_->bag.write(topic, m.header.stamp, m);
}

void Writer::transform(const std::string& topic, const Transform& t) {
  tf2_msgs::TFMessage m;
  geometry_msgs::TransformStamped s;
  s.header = Impl::header(t.stamp, t.parent);
  s.child_frame_id = t.child;
  s.transform.translation.x = t.tx;
  s.transform.translation.y = t.ty;
  s.transform.translation.z = t.tz;
  s.transform.rotation.x = t.qx;
  s.transform.rotation.y = t.qy;
  s.transform.rotation.z = t.qz;
  s.transform.rotation.w = t.qw;
  m.transforms.push_back(s);
  impl_->bag.write(topic, s.header.stamp, m);
}

void Writer::polygon(const std::string& topic, double stamp, const std::string& frame_id,
                     const std::vector<std::array<float, 3>>& points) {
  geometry_msgs::PolygonStamped m;
  m.header = Impl::header(stamp, frame_id);
  for (const auto& p : points) {
    geometry_msgs::Point32 q;
    q.x = p[0];
    q.y = p[1];
    q.z = p[2];
    m.polygon.points.push_back(q);
  }
  impl_->bag.write(topic, m.header.stamp, m);
}

void Writer::float32(const std::string& topic, double stamp, float value) {
  std_msgs::Float32 m;
  m.data = value;
  impl_->bag.write(topic, ros::Time(stamp), m);
}

void Writer::uint32(const std::string& topic, double stamp, unsigned value) {
  std_msgs::UInt32 m;
  m.data = value;
  impl_->bag.write(topic, ros::Time(stamp), m);
}

}  // namespace varslam::bagfile
