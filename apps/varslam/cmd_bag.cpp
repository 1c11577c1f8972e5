// `varslam bag-from-folder`: a dataset folder written as a ROS 1 bag (TUM or RealSense topic layout).
#include <fmt/format.h>

#include <cstdio>

#include "bag/bag_from_folder.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "io/dataset.hpp"
#include "io/file_problem.hpp"
#include "io/settings_registry.hpp"

namespace varslam::cli {

void add_bag_command(CLI::App& app) {
  struct Opts {
    std::string dataset, settings, out, layout = "tum", images = "raw";
    std::size_t first = 0, max_frames = SIZE_MAX;
    double time_offset = 0;
    std::vector<std::string> overrides;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("bag-from-folder", "Write a dataset folder as a ROS 1 bag (what a robot records)");
  cmd->add_option("--dataset,-d", o->dataset, "Dataset folder (TUM/Bonn/OpenLORIS layout)")
      ->required()
      ->check(kNonEmptyPath);
  cmd->add_option("--out,-o", o->out, "The bag to write (.bag)")->required()->check(kNonEmptyPath);
  cmd->add_option("--settings,-s", o->settings, "Settings YAML (default: <dataset>/settings.yaml): the CameraInfo");
  cmd->add_option("--layout", o->layout,
                  "Topic layout: tum (/camera/rgb/image_color, ...) or realsense "
                  "(/device_0/sensor_*/..., with the depth unit and an infrared stream)")
      ->capture_default_str()
      ->check(CLI::IsMember({"tum", "realsense"}));
  cmd->add_option("--images", o->images,
                  "raw (sensor_msgs/Image), png (CompressedImage, lossless: colour PNG and "
                  "compressedDepth PNG) or jpeg (colour JPEG, lossy; depth compressedDepth PNG)")
      ->capture_default_str()
      ->check(CLI::IsMember({"raw", "png", "jpeg"}));
  cmd->add_option("--first", o->first, "First frame index")->check(kFrameIndex);
  cmd->add_option("--max-frames,-n", o->max_frames, "Write at most this many frames")->check(kFrameCount);
  cmd->add_option("--time-offset", o->time_offset,
                  "Seconds added to every stamp (ground truth included): a bag cannot hold time 0, which datasets "
                  "with a clock from 0 (7-Scenes) start at")
      ->check(finite_range(0.0, 1e9));
  cmd->add_option("--set", o->overrides, "Override a setting: section.key=value (repeatable)");
  cmd->callback([o] {
    if (std::filesystem::path(o->out).extension() != ".bag")
      throw InputError(fmt::format("--out {}: a bag file name ends in .bag", o->out));
    if (o->layout == "realsense" && o->images != "raw")
      throw InputError("--layout realsense writes raw images, as RealSense recordings do; drop --images");
    std::optional<std::filesystem::path> sfile;
    if (!o->settings.empty()) sfile = o->settings;
    Settings settings = settings_for_dataset(o->dataset, sfile);
    apply_setting_overrides(settings, o->overrides);
    const auto dataset = open_dataset(o->dataset, settings);
    check_first_frame(o->first, dataset->size());
    check_output_file(o->out, "bag");
    bag::BagWriteOptions wo;
    wo.layout = o->layout == "tum" ? bag::BagLayout::Tum : bag::BagLayout::RealSense;
    wo.images = o->images == "raw"   ? bag::BagImages::Raw
                : o->images == "png" ? bag::BagImages::Png
                                     : bag::BagImages::Jpeg;
    wo.first = o->first;
    wo.max_frames = o->max_frames;
    wo.time_offset = o->time_offset;
    wo.progress = [](std::size_t done, std::size_t total) {
      if (done % 50 == 0 || done == total) std::fprintf(stderr, "\rbag-from-folder: %zu / %zu frames", done, total);
      if (done == total) std::fprintf(stderr, "\n");
    };
    const bag::BagWriteSummary s = bag::write_bag_from_dataset(*dataset, settings, o->out, wo);
    fmt::print(
        "bag-from-folder: {} frames -> {} (colour {}, depth {}, camera {}, {} ground-truth poses in /tf as "
        "world -> kinect)\n",
        s.frames, o->out, s.rgb_topic, s.depth_topic, s.info_topic, s.groundtruth_poses);
  });
}

}  // namespace varslam::cli
