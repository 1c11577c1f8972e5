// `varslam run`: SLAM over a dataset folder (TUM RGB-D / Bonn / OpenLORIS layouts, or a synthetic sequence).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "cli_common.hpp"
#include "bag/bag_dataset.hpp"
#include "core/error.hpp"
#include "commands.hpp"
#include "io/dataset.hpp"
#include "io/trajectory_io.hpp"
#include "viewer/live_viewer.hpp"

namespace varslam::cli {
namespace {

template <typename Opts>
std::unique_ptr<viewer::LiveViewer> start_viewer(const Opts& o, const Dataset& dataset, const run::RunOptions& ro) {
  viewer::LiveViewerOptions vo;
  vo.server.address = o.viewer_address;
  vo.server.port = o.viewer_port;
  vo.max_frame_rate = o.viewer_fps;
  vo.dense.rate = o.viewer_dense_rate;
  vo.title = dataset.root().filename().string();
  const auto gt = ro.groundtruth ? ro.groundtruth : dataset.groundtruth();
  if (gt && std::filesystem::exists(*gt)) {
    try {
      vo.groundtruth = read_tum_trajectory(*gt);
    } catch (const InputError&) {
      // The run reads it too and says what is wrong with it.
    }
  }
  auto v = std::make_unique<viewer::LiveViewer>(vo);
  if (o.viewer_address != "127.0.0.1" && o.viewer_address != "localhost" && o.viewer_address != "::1")
    spdlog::warn("viewer: listening on {}, not only this machine: anyone who reaches it sees the run",
                 o.viewer_address);
  spdlog::info("viewer: open {} in a browser", v->url());
  return v;
}

}  // namespace

void add_run_command(CLI::App& app) {
  struct Opts {
    std::string dataset, settings, out = "out/run", groundtruth, save_map, load_map;
    bag::BagTopics topics;
    bool realtime = false, pace = false, drop_late = false, quiet = false, localization_only = false,
         dense_map = false;
    bool viewer = false, viewer_hold = false, viewer_wait = false;
    std::string viewer_address = "127.0.0.1";
    int viewer_port = 0;
    double viewer_fps = 15;
    double viewer_dense_rate = 0.5;
    std::size_t first = 0, max_frames = SIZE_MAX;
    double min_tracked_share = 0.5;
    std::vector<std::string> overrides;
    std::vector<std::size_t> debug_frames;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("run", "Run SLAM on a dataset folder and write trajectory, map and metrics");
  cmd->add_option("--dataset,-d", o->dataset, "Dataset folder (TUM/Bonn/OpenLORIS layout) or a ROS 1 .bag file")
      ->required()
      ->check(kNonEmptyPath);
  cmd->add_option("--topic-rgb", o->topics.rgb, "Bag input: the colour image topic (default: found by type and name)");
  cmd->add_option("--topic-depth", o->topics.depth, "Bag input: the depth image topic (default: found by type and name)");
  cmd->add_option("--topic-info", o->topics.info,
                  "Bag input: the colour camera's CameraInfo topic (default: the one beside the colour topic)");
  cmd->add_option("--gt-frame", o->topics.gt_frame,
                  "Bag input: ground truth is the /tf pose of this child frame (e.g. /kinect in TUM bags)");
  cmd->add_option("--settings,-s", o->settings, "Settings YAML (default: <dataset>/settings.yaml)");
  cmd->add_option("--out,-o", o->out, "Output folder")->capture_default_str()->check(kNonEmptyPath);
  cmd->add_option("--groundtruth", o->groundtruth, "Ground truth TUM file (default: <dataset>/groundtruth.txt)")
      ->check(kNonEmptyPath);
  cmd->add_flag("--realtime", o->realtime, "Real-time mode: local mapping on its own thread");
  cmd->add_flag("--pace", o->pace, "With --realtime: feed frames at the dataset's frame rate");
  cmd->add_flag("--drop-late", o->drop_late,
                "With --pace: drop a frame when tracking is free only after the next one has arrived, as a live "
                "sensor does (without it such frames are tracked late and counted)");
  cmd->add_option("--first", o->first, "First frame index")->check(kFrameIndex);
  cmd->add_option("--max-frames,-n", o->max_frames, "Process at most this many frames")->check(kFrameCount);
  cmd->add_option("--min-tracked-share", o->min_tracked_share,
                  "A run tracking a smaller share of its frames fails (exit 4); 0 accepts any run")
      ->capture_default_str()
      ->check(finite_range(0.0, 1.0));
  cmd->add_option("--save-map", o->save_map, "Write the final map here (docs/map_format.md)")
      ->check(kNonEmptyPath);
  cmd->add_flag("--dense-map", o->dense_map,
                "Fuse a dense map of the static scene, movers left out: <out>/dense_mesh.ply and dense_map.bt "
                "(settings section dense)");
  cmd->add_option("--load-map", o->load_map, "Start from this saved map: the first frames relocalize in it")
      ->check(kNonEmptyPath);
  cmd->add_flag("--localization-only", o->localization_only,
                "With --load-map: track in the loaded map without extending it (no keyframes, no points)");
  cmd->add_flag("--viewer", o->viewer, "Watch the run live in a browser (the address is printed on start)");
  cmd->add_option("--viewer-port", o->viewer_port, "The viewer's port (0: a free one)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--viewer-address", o->viewer_address,
                  "Listen on this address instead of loopback (reachable from the network: use with care)")
      ->capture_default_str()
      ->check(kListenAddress);
  cmd->add_option("--viewer-fps", o->viewer_fps,
                  "Frames per second sent to the browser at most (lower it when the browser shares a small machine)")
      ->capture_default_str()
      ->check(finite_range(0.5, 60.0));
  cmd->add_option("--viewer-dense-rate", o->viewer_dense_rate,
                  "With --dense-map: updates of the dense map's layer per second at most (each sends only the "
                  "regions that changed)")
      ->capture_default_str()
      ->check(finite_range(0.05, 10.0));
  cmd->add_flag("--viewer-hold", o->viewer_hold, "Keep the viewer up after the run until Ctrl+C");
  cmd->add_flag("--viewer-wait", o->viewer_wait, "Start the run only once a browser is connected");
  cmd->add_option("--set", o->overrides, "Override a setting: section.key=value (repeatable)");
  cmd->add_flag("--quiet,-q", o->quiet, "No progress line");
  cmd->add_option("--debug-frames", o->debug_frames,
                  "Frame indices for which the semantic filter's stages are drawn into <out>/semantic_stages_*.png")
      ->delimiter(',');
  cmd->callback([o] {
    std::optional<std::filesystem::path> sfile;
    if (!o->settings.empty()) sfile = o->settings;
    const bool bag = bag::is_bag_path(o->dataset);
    const bag::BagTopics& t = o->topics;
    if (!bag && !(t.rgb.empty() && t.depth.empty() && t.info.empty() && t.gt_frame.empty()))
      throw InputError(fmt::format("--topic-rgb, --topic-depth, --topic-info and --gt-frame are for .bag input; {} is "
                                   "not a .bag file",
                                   o->dataset));
    Settings settings = bag ? bag::settings_for_bag(o->dataset, sfile, t) : settings_for_dataset(o->dataset, sfile);
    if (o->dense_map) o->overrides.insert(o->overrides.begin(), "dense.enabled=true");
    apply_setting_overrides(settings, o->overrides);
    auto dataset = bag ? bag::open_bag_dataset(o->dataset, settings, t) : open_dataset(o->dataset, settings);
    check_first_frame(o->first, dataset->size());
    run::RunOptions ro;
    ro.mode = o->realtime ? RunMode::RealTime : RunMode::Deterministic;
    ro.pace = o->pace;
    ro.drop_late = o->drop_late;
    ro.first = o->first;
    ro.max_frames = o->max_frames;
    ro.progress = !o->quiet;
    ro.debug_frames.insert(o->debug_frames.begin(), o->debug_frames.end());
    if (!o->groundtruth.empty()) ro.groundtruth = o->groundtruth;
    ro.min_tracked_share = o->min_tracked_share;
    if (!o->save_map.empty()) ro.save_map = o->save_map;
    if (!o->load_map.empty()) ro.load_map = o->load_map;
    ro.localization_only = o->localization_only;
    ro.stop = &stop_on_signals();
    std::unique_ptr<viewer::LiveViewer> live_viewer;
    if (o->viewer) {
      live_viewer = start_viewer(*o, *dataset, ro);
      ro.observers.push_back(live_viewer.get());
      if (o->viewer_wait) {
        spdlog::info("viewer: waiting for a browser at {}", live_viewer->url());
        while (live_viewer->clients() == 0 && !ro.stop->load())
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    }
    const run::RunSummary s = run::run_slam(*dataset, settings, ro, o->out);
    if (live_viewer) {
      const viewer::LiveViewerStats v = live_viewer->stats();
      spdlog::info("viewer: {} frames sent of {} ({} maps); {:.3f} ms per frame on the tracking thread (max {:.2f})",
                   v.frames_sent, v.frames_seen, v.maps_encoded,
                   v.observer_ms_total / static_cast<double>(std::max<std::uint64_t>(1, v.frames_seen)),
                   v.observer_ms_max);
      if (v.dense)
        spdlog::info("viewer: dense layer: {} points in {} regions; {} updates sent {:.1f} KB ({} region messages); "
                     "an update took {:.1f} ms of CPU at most to read and encode ({:.1f} ms in all; {:.0f} ms wall at idle "
                     "priority), the largest was {:.1f} KB",
                     v.dense->points, v.dense->regions, v.dense->updates,
                     static_cast<double>(v.dense->bytes_sent) / 1024.0, v.dense->regions_sent, v.dense->max_update_cpu_ms,
                     v.dense->update_cpu_ms, v.dense->max_update_ms,
                     static_cast<double>(v.dense->max_update_bytes) / 1024.0);
    }
    write_report_for_run(s.out_dir, o->dataset);
    print_run_summary(s);
    if (live_viewer && o->viewer_hold && !s.interrupted) {
      spdlog::info("viewer: the run is over; {} keeps showing it until Ctrl+C", live_viewer->url());
      wait_for_stop();
    }
    if (s.map_error) throw InputError(fmt::format("--save-map: {}; the other outputs are in {}", *s.map_error,
                                                  s.out_dir.string()));
    if (s.interrupted)
      throw CommandFailed(fmt::format("interrupted after {} frames; what was tracked is in {}", s.frames,
                                      s.out_dir.string()),
                          kExitInterrupted);
    if (s.failure) throw CommandFailed("tracking failed: " + *s.failure, kExitTrackingFailed);
  });
}

}  // namespace varslam::cli
