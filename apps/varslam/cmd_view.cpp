// `varslam view`: a finished run in the browser, the way `varslam run --viewer` shows a running one, with a slider
// through its frames.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "io/dataset.hpp"
#include "viewer/run_replay.hpp"
#include "viewer/viewer_server.hpp"

namespace varslam::cli {
namespace {

/// The dataset the run read (metrics.json "dataset"), when it is still there.
std::unique_ptr<Dataset> dataset_of_run(const std::filesystem::path& run_dir, const std::string& explicit_dataset) {
  std::filesystem::path dir = explicit_dataset;
  if (dir.empty()) {
    std::ifstream in(run_dir / "metrics.json");
    if (!in) return nullptr;
    try {
      const auto m = nlohmann::json::parse(in);
      if (m.contains("dataset")) dir = m["dataset"].get<std::string>();
    } catch (const nlohmann::json::exception&) {
      spdlog::warn("{}: unreadable, the run's images are not shown", (run_dir / "metrics.json").string());
      return nullptr;
    }
  }
  if (dir.empty()) return nullptr;
  if (!std::filesystem::is_directory(dir)) {
    spdlog::warn("the run's dataset {} is not there: its images are not shown (--dataset DIR gives it)", dir.string());
    return nullptr;
  }
  return open_dataset(dir, settings_for_dataset(dir, std::nullopt));
}

}  // namespace

void add_view_command(CLI::App& app) {
  struct Opts {
    std::string run, map, dataset, address = "127.0.0.1";
    int port = 0;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("view", "Show a finished run in the browser: map, trajectories, frames");
  cmd->add_option("--run", o->run, "The run's output folder (varslam run -o)")->required();
  cmd->add_option("--map", o->map, "A map saved by the run (--save-map): keyframes, graph and points");
  cmd->add_option("--dataset,-d", o->dataset, "The run's dataset, for its images (default: the one in metrics.json)");
  cmd->add_option("--port", o->port, "Port (0: a free one)")->capture_default_str()->check(CLI::Range(0, 65535));
  cmd->add_option("--address", o->address, "Listen on this address instead of loopback")
      ->capture_default_str()
      ->check(kListenAddress);
  cmd->callback([o] {
    const std::unique_ptr<Dataset> dataset = dataset_of_run(o->run, o->dataset);
    std::optional<std::filesystem::path> map_file;
    if (!o->map.empty()) map_file = o->map;
    const viewer::FinishedRun run = viewer::load_finished_run(o->run, dataset.get(), map_file);
    viewer::ViewerBoard board;
    board.set_greeting(run.greeting);
    board.set_map(run.map);
    for (const std::string& e : run.log) board.append(e);
    viewer::FrameImageSource images;
    if (dataset) {
      const auto [first, count] = viewer::frames_of_run(*dataset, o->run);
      images = viewer::dataset_images(*dataset, first, count);
    }
    const auto& stop = stop_on_signals();
    viewer::ViewerServer server(board, viewer::load_assets(), {o->address, o->port}, images);
    spdlog::info("viewer: {} frames, {} keyframes, {} map points; open {} in a browser (Ctrl+C ends)", run.frames,
                 run.keyframes, run.map_points, server.url());
    (void)stop;
    wait_for_stop();
    server.stop();
  });
}

}  // namespace varslam::cli
