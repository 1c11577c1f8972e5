#include "bag/bag_dataset.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/error.hpp"
#include "io/depth_image.hpp"
#include "io/frame_list.hpp"
#include "io/settings_registry.hpp"
#include "io/trajectory_io.hpp"

#ifdef VARSLAM_HAVE_ROSBAG
#include "bag/topic_choice.hpp"
#include "bagfile/bag_file.hpp"
#endif

namespace varslam::bag {

namespace fs = std::filesystem;

bool is_bag_path(const fs::path& path) {
  std::error_code ec;
  return path.extension() == ".bag" && !fs::is_directory(path, ec);
}

#ifndef VARSLAM_HAVE_ROSBAG

bool bag_support_built() { return false; }

namespace {
[[noreturn]] void no_support(const fs::path& bag) {
  throw InputError(
      fmt::format("{}: this varslam was built without ROS bag support; install the ROS 1 packages "
                  "(scripts/setup.sh does) and rebuild (scripts/build.sh)",
                  bag.string()));
}
}  // namespace

Settings settings_for_bag(const fs::path& bag, const std::optional<fs::path>&, const BagTopics&) { no_support(bag); }
std::unique_ptr<Dataset> open_bag_dataset(const fs::path& bag, const Settings&, const BagTopics&) { no_support(bag); }

#else

bool bag_support_built() { return true; }

namespace {

constexpr double kMaxAssociationDt = 0.02;
constexpr double kRep118DepthFactor = 1000.0;  // 16-bit depth in ROS is millimetres unless the bag says otherwise

struct OpenBag {
  std::shared_ptr<bagfile::Reader> reader;
  ChosenTopics topics;
};

OpenBag open_bag(const fs::path& bag, const BagTopics& wanted) {
  OpenBag b;
  b.reader = std::make_shared<bagfile::Reader>(bag.string());
  std::vector<TopicEntry> entries;
  for (const auto& t : b.reader->topics()) entries.push_back({t.name, t.type, t.messages});
  b.topics = choose_topics(bag.string(), entries, wanted.rgb, wanted.depth, wanted.info);
  return b;
}

// Stamped entries of an image topic, sorted by stamp (bag order is arrival order), repeated stamps dropped.
std::vector<ListEntry> topic_entries(const bagfile::Reader& reader, const std::string& topic) {
  const std::vector<double> stamps = reader.stamps(topic);
  std::vector<ListEntry> out;
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    if (!std::isfinite(stamps[i])) {
      spdlog::warn("{}:{} message {} has a non-finite stamp; skipped", reader.file(), topic, i);
      continue;
    }
    out.push_back({stamps[i], std::to_string(i), fmt::format("{}:{} message {}", reader.file(), topic, i)});
  }
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
  const auto dup =
      std::unique(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.timestamp == b.timestamp; });
  if (dup != out.end()) {
    spdlog::warn("{}:{}: {} messages repeat an earlier stamp; the first of each is used", reader.file(), topic,
                 std::distance(dup, out.end()));
    out.erase(dup, out.end());
  }
  return out;
}

double median_frame_interval(const std::vector<ListEntry>& e) {
  std::vector<double> dt;
  for (std::size_t i = 1; i < e.size(); ++i) dt.push_back(e[i].timestamp - e[i - 1].timestamp);
  if (dt.empty()) return 0;
  std::nth_element(dt.begin(), dt.begin() + static_cast<long>(dt.size() / 2), dt.end());
  return dt[dt.size() / 2];
}

class BagDataset final : public Dataset {
 public:
  BagDataset(fs::path path, OpenBag bag, std::vector<FramePair> frames, const Settings& settings,
             std::optional<fs::path> groundtruth)
      : path_(std::move(path)),
        bag_(std::move(bag)),
        frames_(std::move(frames)),
        width_(settings.camera.width),
        height_(settings.camera.height),
        depth_factor_(settings.depth_factor),
        groundtruth_(std::move(groundtruth)) {}

  ~BagDataset() override {
    std::error_code ec;
    if (groundtruth_) fs::remove_all(groundtruth_->parent_path(), ec);
  }

  std::size_t size() const override { return frames_.size(); }
  double timestamp(std::size_t i) const override { return frames_.at(i).rgb.timestamp; }
  const fs::path& root() const override { return path_; }
  std::optional<fs::path> groundtruth() const override { return groundtruth_; }
  std::string layout() const override { return "rosbag"; }

  RgbdFrame load(std::size_t i) const override {
    const FramePair& f = frames_.at(i);
    RgbdFrame out;
    out.index = i;
    out.timestamp = f.rgb.timestamp;
    out.rgb_path = f.rgb.where;
    out.depth_path = f.depth.where;
    cv::Mat colour = bag_.reader->image(bag_.topics.rgb, std::stoul(f.rgb.path)).mat;
    if (colour.type() == CV_8UC1) cv::cvtColor(colour, colour, cv::COLOR_GRAY2BGR);
    if (colour.type() != CV_8UC3)
      throw InputError(fmt::format("{}: colour topic {} holds no colour image", f.rgb.where, bag_.topics.rgb));
    check_size(colour, f.rgb.where, "colour");
    out.bgr = colour;
    cv::cvtColor(out.bgr, out.gray, cv::COLOR_BGR2GRAY);

    const bagfile::Image depth = bag_.reader->image(bag_.topics.depth, std::stoul(f.depth.path));
    if (depth.mat.size() != colour.size())
      throw InputError(
          fmt::format("{}: depth image is {}x{} but colour is {}x{}; register depth to colour (a "
                      "RealSense 'aligned_depth_to_color' stream) or choose another --topic-depth",
                      f.depth.where, depth.mat.cols, depth.mat.rows, colour.cols, colour.rows));
    out.depth = to_metres(depth, f.depth.where);
    return out;
  }

 private:
  cv::Mat to_metres(const bagfile::Image& d, const std::string& where) const {
    if (d.mat.type() == CV_16UC1) return depth_to_metres(d.mat, depth_factor_);
    if (d.mat.type() != CV_32FC1)
      throw InputError(
          fmt::format("{}: depth of encoding '{}' is not 16-bit or 32-bit float depth", where, d.encoding));
    cv::Mat m = d.mat.clone();  // float metres; NaN and negative values are "no depth"
    m.forEach<float>([](float& v, const int*) {
      if (!(v > 0) || !std::isfinite(v)) v = 0.0f;
    });
    return m;
  }

  void check_size(const cv::Mat& img, const std::string& where, const char* what) const {
    if (img.cols == width_ && img.rows == height_) return;
    throw InputError(
        fmt::format("{}: {} image is {}x{} but the camera is {}x{}", where, what, img.cols, img.rows, width_, height_));
  }

  fs::path path_;
  OpenBag bag_;
  std::vector<FramePair> frames_;
  int width_, height_;
  double depth_factor_;
  std::optional<fs::path> groundtruth_;
};

// Two /tf poses of the ground-truth frame at one stamp: the same measurement twice, or ambiguous ground truth.
void check_same_pose_at_stamp(const bagfile::Reader& reader, const std::string& frame, const StampedPose& first,
                              const StampedPose& again) {
  const PoseGap gap = pose_gap(first, again);
  if (is_same_measurement(gap)) return;
  throw InputError(fmt::format("{}: --gt-frame {}: two poses at stamp {:.6f}, {:.3f} m and {:.2f} deg apart; the "
                               "ground truth is ambiguous there",
                               reader.file(), frame, again.timestamp, gap.metres, gap.degrees));
}

// Poses of the ground-truth frame from /tf as a TUM file in a folder of its own (removed with the dataset).
fs::path extract_groundtruth(const bagfile::Reader& reader, const std::string& frame) {
  const auto tfs = reader.transforms(frame);
  if (tfs.empty())
    throw InputError(fmt::format("{}: --gt-frame {}: no transform in /tf or /tf_static has child frame '{}'",
                                 reader.file(), frame, frame));
  Trajectory gt;
  for (const auto& t : tfs) {
    StampedPose p;
    p.timestamp = t.stamp;
    p.T_wc = Eigen::Translation3d(t.tx, t.ty, t.tz) * Eigen::Quaterniond(t.qw, t.qx, t.qy, t.qz).normalized();
    if (!gt.empty() && p.timestamp == gt.back().timestamp) check_same_pose_at_stamp(reader, frame, gt.back(), p);
    if (gt.empty() || p.timestamp > gt.back().timestamp) gt.push_back(p);
  }
  std::string tmpl = (fs::temp_directory_path() / "varslam-bag-gt-XXXXXX").string();
  if (!mkdtemp(tmpl.data())) throw InputError("cannot create a temporary folder for the bag's ground truth");
  const fs::path file = fs::path(tmpl) / "groundtruth.txt";
  write_tum_trajectory(gt, file);
  spdlog::info("{}: ground truth from /tf frame '{}' ({} poses, parent '{}')", reader.file(), frame, gt.size(),
               tfs.front().parent);
  return file;
}

}  // namespace

Settings settings_for_bag(const fs::path& bag, const std::optional<fs::path>& file, const BagTopics& wanted) {
  const OpenBag b = open_bag(bag, wanted);
  // Metres per raw step of 16-bit depth, where the bag states it (0: it does not).
  const double units = b.topics.depth_units.empty() ? 0.0 : b.reader->number(b.topics.depth_units).value_or(0.0);
  if (!b.topics.depth_units.empty() && !(units > 0 && units < 1))
    throw InputError(fmt::format("{}:{}: depth unit {} m is not a plausible depth scale", bag.string(),
                                 b.topics.depth_units, units));
  const std::string encoding = b.reader->encoding(b.topics.depth);
  const bool float_depth = encoding.rfind("32FC1", 0) == 0;
  if (file) {
    Settings s = load_settings(*file);
    s.dataset_dir = bag.parent_path();
    if (units > 0 && !setting_given(s, "depth.factor")) {  // the bag's unit is a fact of its data; a given key wins
      s.root["depth"]["factor"] = 1.0 / units;
      s.depth_factor = 1.0 / units;
    }
    spdlog::info("{}: camera from the settings file {} (it wins over the bag's CameraInfo); depth {}", bag.string(),
                 file->string(),
                 float_depth ? std::string("in metres (32FC1)")
                             : fmt::format("factor {} ({})", s.depth_factor,
                                           setting_given(s, "depth.factor") ? "the settings file's"
                                           : units > 0                      ? "the bag's unit"
                                                                            : "default"));
    return s;
  }
  if (b.topics.info.empty())
    throw InputError(
        fmt::format("{}: no CameraInfo topic for the colour images {}; give the camera with --settings "
                    "FILE (config/ has TUM, Bonn and OpenLORIS cameras) or name one with --topic-info",
                    bag.string(), b.topics.rgb));
  const auto info = b.reader->camera_info(b.topics.info);
  if (!info || !(info->fx > 0) || !(info->fy > 0) || info->width <= 0 || info->height <= 0)
    throw InputError(
        fmt::format("{}:{}: the CameraInfo holds no camera (fx, fy, width or height is 0); give the "
                    "camera with --settings FILE",
                    bag.string(), b.topics.info));
  YAML::Node root;
  root["camera"]["fx"] = info->fx;
  root["camera"]["fy"] = info->fy;
  root["camera"]["cx"] = info->cx;
  root["camera"]["cy"] = info->cy;
  root["camera"]["width"] = info->width;
  root["camera"]["height"] = info->height;
  const bool plumb_bob = info->distortion_model.empty() || info->distortion_model == "plumb_bob" ||
                         info->distortion_model == "rational_polynomial";
  const bool distorted = std::any_of(info->d.begin(), info->d.end(), [](double v) { return v != 0; });
  if (distorted && !plumb_bob)
    throw InputError(
        fmt::format("{}:{}: distortion model '{}' is not supported (plumb_bob is); give the camera "
                    "with --settings FILE",
                    bag.string(), b.topics.info, info->distortion_model));
  const char* keys[] = {"k1", "k2", "p1", "p2", "k3"};
  for (std::size_t k = 0; k < 5 && k < info->d.size(); ++k) root["camera"][keys[k]] = info->d[k];
  const double factor = units > 0 ? 1.0 / units : kRep118DepthFactor;
  root["depth"]["factor"] = factor;
  const std::vector<ListEntry> rgb = topic_entries(*b.reader, b.topics.rgb);
  if (const double dt = median_frame_interval(rgb); dt > 0) root["camera"]["fps"] = std::min(1000.0, 1.0 / dt);
  Settings s = settings_from_yaml(root, fs::path(bag.string() + ":" + b.topics.info));
  s.dataset_dir = bag.parent_path();
  spdlog::info("{}: camera from CameraInfo {} (fx {} fy {} cx {} cy {}, {}x{}); depth {}", bag.string(), b.topics.info,
               info->fx, info->fy, info->cx, info->cy, info->width, info->height,
               float_depth ? std::string("in metres (32FC1)")
               : units > 0 ? fmt::format("unit {} m from {}", units, b.topics.depth_units)
                           : std::string("in millimetres (ROS REP 118; the bag states no unit)"));
  return s;
}

std::unique_ptr<Dataset> open_bag_dataset(const fs::path& bag, const Settings& settings, const BagTopics& wanted) {
  OpenBag b = open_bag(bag, wanted);
  const std::vector<ListEntry> rgb = topic_entries(*b.reader, b.topics.rgb);
  const std::vector<ListEntry> depth = topic_entries(*b.reader, b.topics.depth);
  std::vector<FramePair> frames = associate_frames(rgb, depth, kMaxAssociationDt);
  if (frames.empty())
    throw InputError(
        fmt::format("{}: no colour message of {} has a depth message of {} within {} s ({} and {} "
                    "messages)",
                    bag.string(), b.topics.rgb, b.topics.depth, kMaxAssociationDt, rgb.size(), depth.size()));
  if (frames.size() < rgb.size())
    spdlog::info("{}: {} of {} colour frames have no depth within {} s and are dropped", bag.string(),
                 rgb.size() - frames.size(), rgb.size(), kMaxAssociationDt);
  std::optional<fs::path> gt;
  if (!wanted.gt_frame.empty()) gt = extract_groundtruth(*b.reader, wanted.gt_frame);
  spdlog::info("{}: bag, colour {}, depth {}, {} frames{}", bag.string(), b.topics.rgb, b.topics.depth, frames.size(),
               gt ? ", with ground truth" : "");
  return std::make_unique<BagDataset>(bag, std::move(b), std::move(frames), settings, std::move(gt));
}

#endif

}  // namespace varslam::bag
