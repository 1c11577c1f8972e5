#include "run/dataset_run.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "core/error.hpp"
#include "eval/ate.hpp"
#include "eval/rpe.hpp"
#include "io/trajectory_io.hpp"
#include "run/filter_stage_writer.hpp"
#include "run/metrics_recorder.hpp"
#include "run/progress_line.hpp"

namespace varslam::run {
namespace {
using Clock = std::chrono::steady_clock;

// Up to 10 frames spread over the first 10 s: what depth registration decides on.
std::vector<RgbdFrame> registration_samples(const Dataset& ds, std::size_t first, std::size_t count) {
  const std::size_t span = std::min<std::size_t>(count, 300), n = std::min<std::size_t>(span, 10);
  std::vector<RgbdFrame> samples;
  for (std::size_t k = 0; k < n; ++k) {
    try {
      samples.push_back(ds.load(first + k * span / n));
    } catch (const InputError&) {
      // an unreadable frame is reported by the run itself; decide on the others
    }
  }
  return samples;
}

// ATE and RPE against ground truth, into the metrics, with the aligned trajectory next to the others.
void evaluate_against(const std::filesystem::path& gt_path, const Trajectory& traj, const Trajectory& live,
                      const std::vector<double>& stamps, const std::filesystem::path& out_dir, nlohmann::json& m,
                      RunSummary& sum) {
  const Trajectory gt = read_tum_trajectory(gt_path);
  try {
    const AteResult ate = evaluate_ate(gt, traj);
    sum.ate_rmse = ate.stats.rmse;
    sum.ate_max = ate.stats.max;
    const std::size_t covered = count_frames_with_ground_truth(stamps, gt);
    m["ate"] = {{"rmse", ate.stats.rmse}, {"mean", ate.stats.mean}, {"median", ate.stats.median},
                {"std", ate.stats.std}, {"min", ate.stats.min}, {"max", ate.stats.max},
                {"pairs", ate.stats.count}, {"correct_rate", correct_rate(ate.stats.count, covered)}};
    try {
      const RpeResult rpe = evaluate_rpe(gt, traj);
      m["rpe"] = {{"trans_rmse", rpe.translation.rmse}, {"rot_rmse_deg", rpe.rotation_deg.rmse}};
    } catch (const InputError& e) {
      spdlog::warn("RPE not computed: {}", e.what());
    }
    write_tum_trajectory(ate.aligned_estimate, out_dir / "CameraTrajectory_aligned.txt");
    if (live.size() >= 2) {
      // What a live user (a robot) got: each pose when its frame was tracked.
      const AteResult live_ate = evaluate_ate(gt, live);
      m["ate_live"] = {{"rmse", live_ate.stats.rmse}, {"max", live_ate.stats.max}, {"pairs", live_ate.stats.count}};
    }
  } catch (const InputError& e) {
    spdlog::warn("ATE not computed: {}", e.what());
  }
}

}  // namespace

void write_map_ply(const slam::Map& map, const std::filesystem::path& file) {
  std::ofstream out(file);
  if (!out) throw InputError(fmt::format("{}: cannot write the map", file.string()));
  std::vector<Eigen::Vector3d> pts;
  for (const auto& mp : map.map_points())
    if (!mp->is_bad()) pts.push_back(mp->position());
  out << "ply\nformat ascii 1.0\ncomment varslam map points (world frame, metres)\n";
  out << "element vertex " << pts.size() << "\nproperty float x\nproperty float y\nproperty float z\n";
  out << "end_header\n";
  for (const auto& p : pts) out << fmt::format("{:.5f} {:.5f} {:.5f}\n", p.x(), p.y(), p.z());
}

RunSummary run_slam(const Dataset& dataset, const Settings& settings, const RunOptions& options,
                    const std::filesystem::path& out_dir) {
  std::filesystem::create_directories(out_dir);
  const std::size_t first = std::min(options.first, dataset.size());
  const std::size_t count = std::min(options.max_frames, dataset.size() - first);
  if (count == 0) throw InputError(fmt::format("{}: no frames to process", dataset.root().string()));

  Slam slam(settings, SlamOptions{options.mode, nullptr});
  MetricsRecorder metrics;
  slam.add_observer(metrics);
  std::optional<ProgressLine> progress;
  if (options.progress) slam.add_observer(progress.emplace(count));
  std::optional<FilterStageWriter> stages;
  if (!options.debug_frames.empty()) slam.add_observer(stages.emplace(options.debug_frames, out_dir));
  for (Observer* o : options.observers) slam.add_observer(*o);
  slam.calibrate_depth(slam.wants_depth_samples() ? registration_samples(dataset, first, count)
                                                 : std::vector<RgbdFrame>{});

  // Unregistered depth is warped into the colour camera on the prefetch thread, before any stage reads it.
  FramePrefetcher prefetch(dataset, 4, first, count, slam.frame_preparation());
  const auto t_start = Clock::now();
  double first_stamp = 0;
  for (std::size_t n = 0;; ++n) {
    const auto t_load = Clock::now();
    std::optional<RgbdFrame> frame = prefetch.next();
    if (!frame) break;
    metrics.add_load_ms(std::chrono::duration<double, std::milli>(Clock::now() - t_load).count());
    if (n == 0) first_stamp = frame->timestamp;
    if (options.mode == RunMode::RealTime && options.pace) {
      // Feed at the sensor's rate: wait until this frame's time has come.
      std::this_thread::sleep_until(t_start + std::chrono::duration<double>(frame->timestamp - first_stamp));
    }
    slam.track(*frame);
  }
  slam.finish();
  const double wall = std::chrono::duration<double>(Clock::now() - t_start).count();
  progress.reset();

  RunSummary sum;
  sum.out_dir = out_dir;
  const SlamSummary s = slam.summary();
  sum.frames = metrics.frames();
  sum.tracked = metrics.tracked();
  sum.lost = sum.frames - sum.tracked;
  sum.segments = s.segments;
  sum.keyframes = s.keyframes;
  sum.map_points = s.map_points;
  sum.wall_seconds = wall;
  sum.fps = static_cast<double>(sum.frames) / std::max(wall, 1e-9);

  const Trajectory traj = slam.camera_trajectory();
  write_tum_trajectory(traj, out_dir / "CameraTrajectory.txt");
  write_tum_trajectory(slam.keyframe_trajectory(), out_dir / "KeyFrameTrajectory.txt");
  write_tum_trajectory(slam.live_trajectory(), out_dir / "LiveTrajectory.txt");
  write_map_ply(slam.map(), out_dir / "map.ply");

  nlohmann::json m = metrics.metrics(slam);
  m["dataset"] = dataset.root().string();
  m["wall_seconds"] = wall;
  m["fps"] = sum.fps;
  const auto gt_path = options.groundtruth ? options.groundtruth : dataset.groundtruth();
  if (gt_path && std::filesystem::exists(*gt_path) && traj.size() >= 2)
    evaluate_against(*gt_path, traj, slam.live_trajectory(), metrics.frame_timestamps(), out_dir, m, sum);
  sum.metrics = m;
  std::ofstream(out_dir / "metrics.json") << m.dump(2) << "\n";
  return sum;
}

}  // namespace varslam::run
