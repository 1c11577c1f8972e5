#include "bag/bag_from_folder.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cerrno>
#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "core/error.hpp"
#include "io/boxes_io.hpp"
#include "io/file_problem.hpp"
#include "io/trajectory_io.hpp"

#ifdef VARSLAM_HAVE_ROSBAG
#include "bagfile/bag_file.hpp"
#endif

namespace varslam::bag {

namespace fs = std::filesystem;

#ifndef VARSLAM_HAVE_ROSBAG

BagWriteSummary write_bag_from_dataset(const Dataset&, const Settings&, const fs::path& out, const BagWriteOptions&) {
  throw InputError(
      fmt::format("{}: this varslam was built without ROS bag support; install the ROS 1 packages "
                  "(scripts/setup.sh does) and rebuild (scripts/build.sh)",
                  out.string()));
}

#else

namespace {

struct LayoutTopics {
  const char *rgb, *depth, *rgb_info, *depth_info, *depth_units, *rgb_frame, *depth_frame, *people;
};

constexpr LayoutTopics kTumTopics{"/camera/rgb/image_color",     "/camera/depth/image",
                                  "/camera/rgb/camera_info",     "/camera/depth/camera_info",
                                  "/camera/depth/depth_units",   "/openni_rgb_optical_frame",
                                  "/openni_depth_optical_frame", "/camera/rgb/people"};
constexpr LayoutTopics kRealSenseTopics{"/device_0/sensor_1/Color_0/image/data",
                                        "/device_0/sensor_0/Depth_0/image/data",
                                        "/device_0/sensor_1/Color_0/info/camera_info",
                                        "/device_0/sensor_0/Depth_0/info/camera_info",
                                        "/device_0/sensor_0/option/Depth Units/value",
                                        "camera_color_optical_frame",
                                        "camera_depth_optical_frame",
                                        "/device_0/sensor_1/Color_0/people"};
constexpr char kRealSenseInfrared[] = "/device_0/sensor_0/Infrared_1/image/data";

// The raw 16-bit depth of a frame: its PNG where the dataset has one, else the metres scaled back.
cv::Mat raw_depth(const RgbdFrame& f, double factor) {
  if (!f.depth_path.empty() && fs::is_regular_file(f.depth_path)) {
    cv::Mat raw = cv::imread(f.depth_path, cv::IMREAD_UNCHANGED);
    if (raw.type() == CV_16UC1) return raw;
  }
  cv::Mat raw(f.depth.size(), CV_16UC1);
  for (int y = 0; y < raw.rows; ++y)
    for (int x = 0; x < raw.cols; ++x)
      raw.at<std::uint16_t>(y, x) = static_cast<std::uint16_t>(std::lround(f.depth.at<float>(y, x) * factor));
  return raw;
}

bagfile::CameraInfo camera_info(const PinholeCamera& c, const char* frame) {
  bagfile::CameraInfo info;
  info.frame_id = frame;
  info.width = c.width;
  info.height = c.height;
  info.fx = c.fx;
  info.fy = c.fy;
  info.cx = c.cx;
  info.cy = c.cy;
  info.distortion_model = "plumb_bob";
  info.d = {c.k1, c.k2, c.p1, c.p2, c.k3};
  return info;
}

}  // namespace

BagWriteSummary write_bag_from_dataset(const Dataset& dataset, const Settings& settings, const fs::path& out,
                                       const BagWriteOptions& options) {
  const LayoutTopics& t = options.layout == BagLayout::Tum ? kTumTopics : kRealSenseTopics;
  const bool realsense = options.layout == BagLayout::RealSense;
  const std::size_t first = std::min(options.first, dataset.size());
  const std::size_t end = first + std::min(options.max_frames, dataset.size() - first);
  if (first == end) throw InputError(fmt::format("{}: no frames to write", dataset.root().string()));
  // ROS time 0 means "no stamp", and bags refuse it: datasets whose clock starts at 0 need an offset.
  if (const double t0 = dataset.timestamp(first) + options.time_offset; !(t0 >= 1e-6))
    throw InputError(
        fmt::format("{}: the first frame's timestamp is {:.6f} s{}; a ROS bag cannot hold times at or "
                    "before 0 (time 0 means 'unset'): give --time-offset 1 (added to every stamp, "
                    "ground truth included)",
                    dataset.root().string(), dataset.timestamp(first),
                    options.time_offset != 0 ? fmt::format(" (with offset {})", options.time_offset) : std::string()));
  // Read before the frames are written, so a broken file fails at once.
  const Trajectory groundtruth = dataset.groundtruth() ? read_tum_trajectory(*dataset.groundtruth()) : Trajectory{};
  if (out.has_parent_path()) fs::create_directories(out.parent_path());
  const fs::path tmp = out.string() + ".partial";
  BagWriteSummary summary;
  summary.info_topic = t.rgb_info;
  try {
    bagfile::Writer w(tmp.string());
    const double dt = options.time_offset;
    const double t0 = dataset.timestamp(first) + dt;
    // The depth unit (metres per raw step) the 16-bit depth needs; 32-bit float depth is metres already.
    const bool raw16 = realsense || options.images != BagImages::Raw;
    if (realsense) w.uint32("/file_version", t0, 3);
    if (raw16) w.float32(t.depth_units, t0, static_cast<float>(1.0 / settings.depth_factor));
    w.camera_info(t.rgb_info, t0, camera_info(settings.camera, t.rgb_frame));
    w.camera_info(t.depth_info, t0, camera_info(settings.camera, t.depth_frame));
    std::string rgb_topic = t.rgb, depth_topic = t.depth;
    if (options.images != BagImages::Raw) {
      rgb_topic += "/compressed";
      depth_topic += "/compressedDepth";
    }
    const fs::path boxes_file = dataset.root() / "boxes.txt";
    const BoxesByTime boxes = fs::is_regular_file(boxes_file) ? read_boxes_file(boxes_file) : BoxesByTime{};
    for (std::size_t i = first; i < end; ++i) {
      const RgbdFrame f = dataset.load(i);
      const double stamp = f.timestamp + dt;
      if (const Detections people = boxes_near(boxes, f.timestamp, 1e-4); !people.empty()) {  // before the images
        std::vector<std::array<float, 3> > corners;
        for (const Detection& d : people) {
          corners.push_back({d.box.x, d.box.y, d.score});
          corners.push_back({d.box.x + d.box.width, d.box.y + d.box.height, d.score});
        }
        w.polygon(t.people, stamp, t.rgb_frame, corners);
        ++summary.box_frames;
      }
      switch (options.images) {
        case BagImages::Raw:
          w.image(rgb_topic, stamp, t.rgb_frame, f.bgr, realsense ? "rgb8" : "bgr8");
          if (realsense)
            w.image(depth_topic, stamp, t.depth_frame, raw_depth(f, settings.depth_factor), "mono16");
          else
            w.image(depth_topic, stamp, t.depth_frame, f.depth, "32FC1");
          break;
        case BagImages::Png:
        case BagImages::Jpeg:
          w.compressed(rgb_topic, stamp, t.rgb_frame, f.bgr,
                       options.images == BagImages::Png ? "bgr8; png compressed bgr8" : "bgr8; jpeg compressed bgr8");
          w.compressed(depth_topic, stamp, t.depth_frame, raw_depth(f, settings.depth_factor),
                       "16UC1; compressedDepth png");
          break;
      }
      if (realsense) w.image(kRealSenseInfrared, stamp, "camera_infra1_optical_frame", f.gray, "mono8");
      ++summary.frames;
      if (options.progress) options.progress(summary.frames, end - first);
    }
    for (const StampedPose& p : groundtruth) {
      if (p.timestamp < dataset.timestamp(first) - 1.0 || p.timestamp > dataset.timestamp(end - 1) + 1.0) continue;
      const Eigen::Quaterniond q(p.T_wc.rotation());
      const Eigen::Vector3d x = p.T_wc.translation();
      if (p.timestamp + dt < 1e-6) continue;
      w.transform("/tf", {p.timestamp + dt, "world", "kinect", x.x(), x.y(), x.z(), q.x(), q.y(), q.z(), q.w()});
      ++summary.groundtruth_poses;
    }
    summary.rgb_topic = rgb_topic;
    summary.depth_topic = depth_topic;
    w.close();
  } catch (const InputError&) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  } catch (const std::exception& e) {
    // The bag library's own words lack the reason; the failed write's errno has it (a full disk, a quota).
    const int err = errno;
    std::error_code ec;
    fs::remove(tmp, ec);
    const bool known = err == ENOSPC || err == EDQUOT || err == EROFS || err == EACCES || err == EIO;
    throw InputError(fmt::format("{}: cannot write the bag: {}", out.string(), known ? describe_errno(err) : e.what()));
  }
  fs::rename(tmp, out);
  spdlog::info("{}: {} frames ({}, {}), {} ground-truth poses as /tf world -> kinect", out.string(), summary.frames,
               summary.rgb_topic, summary.depth_topic, summary.groundtruth_poses);
  return summary;
}

#endif

}  // namespace varslam::bag
