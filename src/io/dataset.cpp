#include "io/dataset.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cerrno>
#include <optional>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "io/depth_image.hpp"
#include "io/file_problem.hpp"
#include "io/frame_list.hpp"
#include "io/image_decoding.hpp"

namespace varslam {
namespace {

namespace fs = std::filesystem;

// A median depth outside this range over a whole frame almost surely means a wrong depth factor.
constexpr double kMinPlausibleMedianDepth = 0.05;
constexpr double kMaxPlausibleMedianDepth = 20.0;
constexpr double kMaxAssociationDt = 0.02;

struct LayoutFiles {
  std::string name;
  const char* rgb_list;
  const char* depth_list;
};

const LayoutFiles kTum{"tum", "rgb.txt", "depth.txt"};
const LayoutFiles kOpenLoris{"openloris", "color.txt", "aligned_depth.txt"};

// OpenLORIS is recognised by either of its list names; everything else is treated as TUM.
const LayoutFiles& detect_layout(const fs::path& dir) {
  if (fs::exists(dir / kOpenLoris.rgb_list) || fs::exists(dir / kOpenLoris.depth_list)) return kOpenLoris;
  return kTum;
}

// Both supported layouts are "two lists of stamped images under one folder"; only the names differ.
class ListedRgbdDataset final : public Dataset {
 public:
  ListedRgbdDataset(fs::path root, std::string layout, std::vector<FramePair> frames, const Settings& settings)
      : root_(std::move(root)),
        layout_(std::move(layout)),
        frames_(std::move(frames)),
        width_(settings.camera.width),
        height_(settings.camera.height),
        depth_factor_(settings.depth_factor),
        settings_name_(settings.source.empty() ? std::string("default settings") : settings.source.string()) {
    if (fs::exists(root_ / "groundtruth.txt")) groundtruth_ = root_ / "groundtruth.txt";
  }

  std::size_t size() const override { return frames_.size(); }
  double timestamp(std::size_t i) const override { return frames_.at(i).rgb.timestamp; }
  const fs::path& root() const override { return root_; }
  std::optional<fs::path> groundtruth() const override { return groundtruth_; }
  std::string layout() const override { return layout_; }

  RgbdFrame load(std::size_t i) const override {
    const FramePair& f = frames_.at(i);
    RgbdFrame out;
    out.index = i;
    out.timestamp = f.rgb.timestamp;
    out.rgb_path = (root_ / f.rgb.path).string();
    out.depth_path = (root_ / f.depth.path).string();

    check_exists(f.rgb, out.rgb_path);
    out.bgr = decode_colour_image(read_image_file(f.rgb, out.rgb_path));
    if (out.bgr.empty()) throw InputError(fmt::format("{}: cannot decode image {}", f.rgb.where, out.rgb_path));
    check_size(out.bgr, f.rgb, out.rgb_path);
    cv::cvtColor(out.bgr, out.gray, cv::COLOR_BGR2GRAY);

    check_exists(f.depth, out.depth_path);
    const cv::Mat raw = decode_unchanged_image(read_image_file(f.depth, out.depth_path));
    if (raw.empty())
      throw InputError(fmt::format("{}: cannot decode depth image {}", f.depth.where, out.depth_path));
    if (raw.type() != CV_16UC1)
      throw InputError(fmt::format("{}: depth image {} is {}-bit with {} channel(s); expected a 16-bit single "
                                   "channel PNG",
                                   f.depth.where, out.depth_path, raw.elemSize1() * 8, raw.channels()));
    check_size(raw, f.depth, out.depth_path);
    out.depth = depth_to_metres(raw, depth_factor_);
    check_depth_scale(out.depth, out.depth_path);
    return out;
  }

  struct ListedFileProblems {
    std::size_t missing = 0, unreadable = 0;
    std::string first_missing, first_unreadable;
  };

  // Listed files that are not on disk or cannot be reached (a symlink loop, a folder without permission): counted
  // once at open, so a broken copy is reported early; the run skips those frames.
  ListedFileProblems check_listed_files() const {
    ListedFileProblems p;
    for (const auto& f : frames_)
      for (const ListEntry* e : {&f.rgb, &f.depth}) {
        std::error_code ec;
        const fs::path file = root_ / e->path;
        if (fs::exists(file, ec)) continue;
        if (ec && p.unreadable++ == 0)
          p.first_unreadable = fmt::format("{} ({}): {}", file.string(), e->where, describe_error(ec));
        if (!ec && p.missing++ == 0) p.first_missing = fmt::format("{} ({})", file.string(), e->where);
      }
    return p;
  }

 private:
  // A loop of symbolic links or a folder without permission is an unreadable frame like a missing one.
  static void check_exists(const ListEntry& e, const std::string& path) {
    std::error_code ec;
    const bool exists = fs::exists(path, ec);
    if (ec) throw InputError(fmt::format("{}: cannot read image {}: {}", e.where, path, describe_error(ec)));
    if (!exists) throw InputError(fmt::format("{}: listed image {} does not exist", e.where, path));
  }

  // The file's bytes, once it is known to be a PNG or JPEG, the formats RGB-D datasets use (the decoders would give
  // no image for anything else; this names the problem).
  static std::vector<std::uint8_t> read_image_file(const ListEntry& e, const std::string& path) {
    std::optional<std::vector<std::uint8_t>> bytes = read_file_bytes(path);
    if (!bytes) throw InputError(fmt::format("{}: cannot read image {}: {}", e.where, path, describe_errno(errno)));
    if (is_png_or_jpeg_file(*bytes)) return std::move(*bytes);
    throw InputError(fmt::format("{}: {} is not a PNG or JPEG image", e.where, path));
  }

  void check_size(const cv::Mat& img, const ListEntry& e, const std::string& path) const {
    if (img.cols == width_ && img.rows == height_) return;
    throw InputError(fmt::format("{}: image {} is {}x{} but the camera in {} is {}x{}", e.where, path, img.cols,
                                 img.rows, settings_name_, width_, height_));
  }

  // Warns once per dataset: the numbers of the first implausible frame are enough to spot the mistake.
  void check_depth_scale(const cv::Mat& metres, const std::string& path) const {
    const double median = median_valid_depth(metres);
    if (median <= 0 || (median >= kMinPlausibleMedianDepth && median <= kMaxPlausibleMedianDepth)) return;
    if (warned_depth_scale_.exchange(true)) return;
    spdlog::warn("{}: median valid depth is {:.3f} m with depth factor {} (from {}); expected {}..{} m. Is the "
                 "depth factor right (TUM/Bonn 5000, OpenLORIS/7-Scenes 1000)?",
                 path, median, depth_factor_, settings_name_, kMinPlausibleMedianDepth, kMaxPlausibleMedianDepth);
  }

  fs::path root_;
  std::string layout_;
  std::vector<FramePair> frames_;
  int width_, height_;
  double depth_factor_;
  std::string settings_name_;
  std::optional<fs::path> groundtruth_;
  mutable std::atomic<bool> warned_depth_scale_{false};
};

std::vector<FramePair> read_frames(const fs::path& dir, const LayoutFiles& layout) {
  if (fs::exists(dir / "associations.txt")) {
    auto frames = read_associations(dir / "associations.txt");
    if (frames.empty()) throw InputError(fmt::format("{}: no frames listed", (dir / "associations.txt").string()));
    return frames;
  }
  for (const char* list : {layout.rgb_list, layout.depth_list})
    if (!fs::exists(dir / list))
      throw InputError(fmt::format("{}: missing list file {} ({} layout needs {} and {}, or associations.txt)",
                                   dir.string(), list, layout.name, layout.rgb_list, layout.depth_list));
  const auto rgb = read_frame_list(dir / layout.rgb_list);
  const auto depth = read_frame_list(dir / layout.depth_list);
  auto frames = associate_frames(rgb, depth, kMaxAssociationDt);
  if (frames.empty())
    throw InputError(fmt::format("{}: no {} entry has a {} entry within {} s ({} and {} entries)", dir.string(),
                                 layout.rgb_list, layout.depth_list, kMaxAssociationDt, rgb.size(), depth.size()));
  if (frames.size() < rgb.size())
    spdlog::info("{}: {} of {} colour frames have no depth within {} s and are dropped", dir.string(),
                 rgb.size() - frames.size(), rgb.size(), kMaxAssociationDt);
  return frames;
}

}  // namespace

std::unique_ptr<Dataset> open_dataset(const std::filesystem::path& dir, const Settings& settings) {
  if (!fs::exists(dir)) throw InputError(fmt::format("{}: dataset folder does not exist", dir.string()));
  if (!fs::is_directory(dir)) throw InputError(fmt::format("{}: not a folder", dir.string()));
  const LayoutFiles& layout = detect_layout(dir);
  auto ds = std::make_unique<ListedRgbdDataset>(dir, layout.name, read_frames(dir, layout), settings);
  const auto problems = ds->check_listed_files();
  if (problems.missing > 0)
    spdlog::warn("{}: {} listed images are missing, first {}", dir.string(), problems.missing, problems.first_missing);
  if (problems.unreadable > 0)
    spdlog::warn("{}: {} listed images cannot be read, first {}", dir.string(), problems.unreadable,
                 problems.first_unreadable);
  spdlog::info("{}: {} layout, {} frames{}", dir.string(), layout.name, ds->size(),
               ds->groundtruth() ? ", with ground truth" : "");
  return ds;
}

Settings settings_for_dataset(const std::filesystem::path& dir, const std::optional<std::filesystem::path>& file) {
  // Anything named settings.yaml (a link to nowhere, a folder, a file we may not read) is meant as the settings:
  // reading it says what is wrong, instead of running with the default camera.
  const fs::path in_folder = dir / "settings.yaml";
  std::error_code ec;
  const bool named = fs::exists(fs::symlink_status(in_folder, ec));
  Settings s = file ? load_settings(*file) : named ? load_settings(in_folder) : default_settings();
  s.dataset_dir = dir;
  if (!s.source.empty()) return s;
  if (fs::is_directory(dir) && &detect_layout(dir) == &kOpenLoris) s.depth_factor = 1000.0;
  spdlog::warn("{}: no settings file given and no settings.yaml in the folder; using default settings (TUM fr1 "
               "camera fx {} fy {} cx {} cy {}, {}x{}, depth factor {})",
               dir.string(), s.camera.fx, s.camera.fy, s.camera.cx, s.camera.cy, s.camera.width, s.camera.height,
               s.depth_factor);
  return s;
}

}  // namespace varslam
