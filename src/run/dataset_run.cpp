#include "run/dataset_run.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <thread>

#include "core/elapsed.hpp"
#include "core/error.hpp"
#include "dense/dense_mapper.hpp"
#include "eval/ate.hpp"
#include "eval/drag_events.hpp"
#include "eval/rpe.hpp"
#include "io/atomic_file.hpp"
#include "io/file_problem.hpp"
#include "io/output_folder.hpp"
#include "io/settings_registry.hpp"
#include "io/trajectory_io.hpp"
#include "run/filter_stage_writer.hpp"
#include "run/metrics_recorder.hpp"
#include "run/progress_line.hpp"

namespace varslam::run {
namespace {
using Clock = std::chrono::steady_clock;

// Up to 20 frames spread over the whole run: what depth registration decides on. Views of different depths make
// the baseline between a separate depth camera and the colour camera observable.
std::vector<RgbdFrame> registration_samples(const Dataset& ds, std::size_t first, std::size_t count) {
  const std::size_t span = count, n = std::min<std::size_t>(span, 20);
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

Alignment to_alignment(const Eigen::Isometry3d& T) {
  Alignment a;
  a.R = T.linear();
  a.t = T.translation();
  return a;
}

Eigen::Isometry3d to_isometry(const Alignment& a) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = a.R;
  T.translation() = a.t;
  return T;
}

// ATE and RPE against ground truth, into the metrics, with the aligned trajectory next to the others. Returns the
// final trajectory's alignment (estimate -> ground truth), nullopt when there is no ATE.
std::optional<Eigen::Isometry3d> evaluate_against(const Trajectory& gt, const Trajectory& traj, const Trajectory& live,
                                                  const std::vector<double>& stamps,
                                                  const std::optional<Eigen::Isometry3d>& map_alignment,
                                                  const std::filesystem::path& out_dir, nlohmann::json& m,
                                                  RunSummary& sum) {
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
      const std::vector<DragEvent> drags = find_drag_events(gt, live);
      sum.ate_live_rmse = live_ate.stats.rmse;
      sum.ate_live_max = live_ate.stats.max;
      sum.dragged_events = drags.size();
      nlohmann::json dj = nlohmann::json::array();
      for (const DragEvent& d : drags) dj.push_back({{"start", d.start}, {"end", d.end}, {"peak_m", d.peak_m}});
      m["ate_live"] = {{"rmse", live_ate.stats.rmse}, {"max", live_ate.stats.max}, {"pairs", live_ate.stats.count},
                       {"dragged_events", drags.size()}, {"drags", dj}};
    }
    if (map_alignment) {
      // In the loaded map's own alignment to ground truth: what a robot localizing in that map gets.
      AteOptions in_map;
      in_map.fixed_alignment = to_alignment(*map_alignment);
      const AteResult fin = evaluate_ate(gt, traj, in_map);
      sum.ate_map_frame_rmse = fin.stats.rmse;
      sum.ate_map_frame_max = fin.stats.max;
      m["ate_map_frame"] = {{"rmse", fin.stats.rmse}, {"max", fin.stats.max}, {"pairs", fin.stats.count},
                            {"correct_rate", correct_rate(fin.stats.count, covered)}};
      if (live.size() >= 2) {
        const AteResult lv = evaluate_ate(gt, live, in_map);
        m["ate_live_map_frame"] = {{"rmse", lv.stats.rmse}, {"max", lv.stats.max}, {"pairs", lv.stats.count},
                                   {"correct_rate", correct_rate(lv.stats.count, covered)}};
      }
    }
    return to_isometry(ate.alignment);
  } catch (const InputError& e) {
    sum.ate_note = fmt::format("not computed: {}", e.what());
  }
  return std::nullopt;
}

// What a run that tracked almost nothing most likely lacked.
std::string likely_cause(const MetricsRecorder& metrics, const Settings& settings) {
  constexpr double kFewKeypoints = 100;     // tracking needs a few hundred; below this the images carry no texture
  constexpr double kLittleDepth = 0.2;      // share of keypoints with depth below which RGB-D tracking cannot work
  if (metrics.frames() == 0) return "no frame was read";
  if (metrics.median_keypoints() < kFewKeypoints)
    return fmt::format("the frames have a median of {:.0f} ORB keypoints (black, blank or tiny images, or orb.n_features "
                       "too small)",
                       metrics.median_keypoints());
  if (metrics.median_depth_share() < kLittleDepth)
    return fmt::format("only {:.0f} % of the keypoints have a depth (depth images all zero or saturated, or "
                       "depth.factor {} wrong for this sensor)",
                       100.0 * metrics.median_depth_share(), settings.depth_factor);
  return "keypoints and depth look usable: fast motion, a wrong camera model, or a scene dominated by movers";
}

// Every file a run may write into its folder (the report is written beside it by the CLI).
std::vector<OutputFile> run_outputs(const RunOptions& options, bool dense) {
  std::vector<OutputFile> out = {{"CameraTrajectory.txt", "trajectory file"},
                                 {"CameraTrajectory_aligned.txt", "trajectory file"},
                                 {"KeyFrameTrajectory.txt", "trajectory file"},
                                 {"LiveTrajectory.txt", "trajectory file"},
                                 {"map.ply", "map"},
                                 {"metrics.json", "metrics file"},
                                 {"report.html", "report"}};
  for (const std::size_t f : options.debug_frames)
    out.push_back({FilterStageWriter::file_name(f), "filter stages image"});
  if (dense) {
    out.push_back({"dense_mesh.ply", "dense mesh"});
    out.push_back({"dense_map.bt", "occupancy map"});
  }
  return out;
}

// Debug frames the run does not reach would draw nothing and say nothing: refuse them before the run.
void check_debug_frames(const std::set<std::size_t>& frames, std::size_t first, std::size_t count,
                        const Dataset& dataset) {
  std::vector<std::size_t> outside;
  for (const std::size_t f : frames)
    if (f < first || f - first >= count) outside.push_back(f);
  if (outside.empty()) return;
  throw InputError(fmt::format("--debug-frames {}: outside the frames this run processes, {} to {} of the {} in {} "
                               "(see --first and --max-frames)",
                               fmt::join(outside, ","), first, first + count - 1, dataset.size(),
                               dataset.root().string()));
}

}  // namespace

nlohmann::json write_dense_map(dense::DenseMapper& d, const std::filesystem::path& out_dir) {
  const auto t0 = Clock::now();
  const dense::Mesh mesh = d.mesh();
  const std::vector<dense::OccupancyVoxel> occ = d.occupancy();
  const double extract_ms = ms_since(t0);
  dense::write_mesh_ply(mesh, out_dir / "dense_mesh.ply");
  dense::write_octomap_bt(occ, d.config().tsdf.voxel_size, out_dir / "dense_map.bt");
  const dense::DenseStats st = d.stats();
  auto pct = [&st](double q) {
    if (st.integrate_ms.empty()) return 0.0;
    std::vector<double> v = st.integrate_ms;
    const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    return v[k];
  };
  std::size_t occupied = 0;
  for (const auto& v : occ) occupied += v.occupied ? 1 : 0;
  return {{"keyframes", st.keyframes},
          {"voxel_size", d.config().tsdf.voxel_size},
          {"fusions", st.integrations},
          {"reintegrations", st.reintegrations},
          {"fuse_ms", {{"median", pct(0.5)}, {"p95", pct(0.95)}}},
          {"final_rebuild_ms", st.final_rebuild_ms},
          {"extract_ms", extract_ms},
          {"blocks", st.blocks},
          {"moving_pixel_share", st.moving_pixel_share},
          {"mesh_vertices", mesh.vertices.size()},
          {"mesh_triangles", mesh.triangles.size()},
          {"occupied_voxels", occupied},
          {"free_voxels", occ.size() - occupied}};
}

// Where the ground truth's camera sits in the colour camera's frame: a separate depth camera's origin when the
// settings say the ground truth tracks it (eval.groundtruth_camera: depth), else nothing.
std::optional<Eigen::Vector3d> groundtruth_camera_offset(const Settings& settings, const Pipeline& slam) {
  if (setting<std::string>(settings, "eval.groundtruth_camera") != "depth") return std::nullopt;
  if (!slam.depth_rig()) {
    spdlog::info("eval.groundtruth_camera: depth, but depth is registered to colour: one camera, nothing to move");
    return std::nullopt;
  }
  const Eigen::Vector3d t = slam.depth_rig()->t_colour_depth;
  spdlog::info("ATE and RPE of the depth camera ({:.1f}, {:.1f}, {:.1f}) cm from the colour camera "
               "(eval.groundtruth_camera: depth)",
               100.0 * t.x(), 100.0 * t.y(), 100.0 * t.z());
  return t;
}

// The trajectory of a camera rigidly mounted at `offset` in the colour camera's frame (both look the same way).
Trajectory moved_to_camera(Trajectory traj, const std::optional<Eigen::Vector3d>& offset) {
  if (offset)
    for (StampedPose& p : traj) p.T_wc.translation() += p.T_wc.linear() * *offset;
  return traj;
}

void write_map_ply(const slam::Map& map, const std::filesystem::path& file) {
  std::vector<Eigen::Vector3d> pts;
  for (const auto& mp : map.map_points())
    if (!mp->is_bad()) pts.push_back(mp->position());
  std::string text = "ply\nformat ascii 1.0\ncomment varslam map points (world frame, metres)\n";
  text += fmt::format("element vertex {}\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
                      pts.size());
  for (const auto& p : pts) text += fmt::format("{:.5f} {:.5f} {:.5f}\n", p.x(), p.y(), p.z());
  write_file_atomically(file, text, "map");
}

RunSummary run_slam(const Dataset& dataset, const Settings& settings, const RunOptions& options,
                    const std::filesystem::path& out_dir) {
  const std::size_t first = std::min(options.first, dataset.size());
  const std::size_t count = std::min(options.max_frames, dataset.size() - first);
  if (count == 0) throw InputError(fmt::format("{}: no frames to process", dataset.root().string()));
  check_debug_frames(options.debug_frames, first, count, dataset);
  // Checked before the run, so a broken file does not cost one.
  const auto gt_path = options.groundtruth ? options.groundtruth : dataset.groundtruth();
  std::optional<Trajectory> groundtruth;
  if (options.groundtruth && !std::filesystem::exists(*options.groundtruth))
    throw InputError(fmt::format("{}: ground truth file not found", options.groundtruth->string()));
  if (gt_path && std::filesystem::exists(*gt_path)) groundtruth = read_tum_trajectory(*gt_path);

  const bool dense = setting<bool>(settings, "dense.enabled");
  const OutputFolder out(out_dir, run_outputs(options, dense));
  if (options.save_map) check_output_file(*options.save_map, "map");  // after the folder: the map may go into it
  Pipeline slam(settings, PipelineOptions{options.mode, nullptr});
  MetricsRecorder metrics;
  slam.add_observer(metrics);
  std::optional<ProgressLine> progress;
  if (options.progress) slam.add_observer(progress.emplace(count));
  std::optional<FilterStageWriter> stages;
  if (!options.debug_frames.empty()) slam.add_observer(stages.emplace(options.debug_frames, out_dir));
  for (Observer* o : options.observers) slam.add_observer(*o);
  double map_load_ms = 0;
  if (options.load_map) {
    const auto t0 = Clock::now();
    slam.load_map(*options.load_map);
    map_load_ms = ms_since(t0);
  }
  if (options.localization_only) slam.set_localization_only(true);
  slam.calibrate_depth(slam.wants_depth_samples() ? registration_samples(dataset, first, count)
                                                 : std::vector<RgbdFrame>{});

  // Unregistered depth is warped into the colour camera on the prefetch thread, before any stage reads it.
  FramePrefetcher prefetch(dataset, 4, first, count, slam.frame_preparation());
  const bool realtime = options.mode == RunMode::RealTime;
  const bool paced = realtime && options.pace;
  std::vector<double> stamps;  // paced: when each frame is due
  if (paced)
    for (std::size_t i = first; i < first + count; ++i) stamps.push_back(dataset.timestamp(i));
  const auto t_start = Clock::now();
  double first_stamp = 0;
  const auto due = [&](double stamp) {
    return t_start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(stamp - first_stamp));
  };
  bool interrupted = false;
  for (std::size_t n = 0;; ++n) {
    if (options.stop && options.stop->load()) {
      interrupted = true;
      break;
    }
    const auto t_load = Clock::now();
    std::optional<RgbdFrame> frame = prefetch.next();
    if (!frame) break;
    metrics.add_load_ms(ms_since(t_load));
    if (n == 0) first_stamp = frame->timestamp;
    Clock::time_point arrival = Clock::now();
    if (paced) {
      // As a sensor delivers: the frame arrives at its time. When tracking is free only after the next frame has
      // arrived too, this one is late: a live camera driver would have dropped it for the newer one.
      const auto next = std::upper_bound(stamps.begin(), stamps.end(), frame->timestamp);
      if (n > 0 && next != stamps.end() && Clock::now() >= due(*next)) {
        metrics.add_late_frame(options.drop_late);
        if (options.drop_late) continue;
      }
      arrival = due(frame->timestamp);
      std::this_thread::sleep_until(arrival);
    }
    slam.track(*frame);
    if (realtime) metrics.add_latency_ms(ms_since(arrival));
  }
  slam.finish();
  const double wall = std::chrono::duration<double>(Clock::now() - t_start).count();
  progress.reset();

  RunSummary sum;
  sum.out_dir = out_dir;
  sum.interrupted = interrupted;
  const PipelineSummary s = slam.summary();
  sum.frames = metrics.frames();
  sum.tracked = metrics.tracked();
  sum.lost = sum.frames - sum.tracked;
  sum.segments = s.segments;
  sum.keyframes = s.keyframes;
  sum.map_points = s.map_points;
  sum.wall_seconds = wall;
  sum.fps = static_cast<double>(sum.frames) / std::max(wall, 1e-9);

  int repaired = 0;
  const Trajectory traj = slam.camera_trajectory(&repaired);
  write_tum_trajectory(traj, out_dir / "CameraTrajectory.txt");
  write_tum_trajectory(slam.keyframe_trajectory(), out_dir / "KeyFrameTrajectory.txt");
  write_tum_trajectory(slam.live_trajectory(), out_dir / "LiveTrajectory.txt");
  write_map_ply(slam.map(), out_dir / "map.ply");

  nlohmann::json m = metrics.metrics(slam);
  if (dense::DenseMapper* d = slam.dense_map()) m["dense_map"] = write_dense_map(*d, out_dir);
  m["final_poses_repaired"] = repaired;
  if (repaired > 0)
    spdlog::warn("{} final pose{} no frame supported (a lone keyframe left misplaced) replaced by the neighbours' "
                 "correction of the live pose",
                 repaired, repaired == 1 ? "" : "s");
  m["dataset"] = dataset.root().string();
  m["wall_seconds"] = wall;
  m["fps"] = sum.fps;
  nlohmann::json skipped = nlohmann::json::array();
  for (const SkippedFrame& f : prefetch.skipped_frames()) skipped.push_back({{"index", f.index}, {"reason", f.reason}});
  m["skipped_frames"] = skipped;
  if (options.load_map)
    m["loaded_map"] = {{"path", options.load_map->string()}, {"load_ms", map_load_ms},
                       {"localization_only", options.localization_only}};
  std::optional<Eigen::Isometry3d> alignment;
  if (groundtruth && traj.size() >= 2) {
    const std::optional<Eigen::Vector3d> offset = groundtruth_camera_offset(settings, slam);
    m["ate_camera"] = offset ? "depth" : "colour";
    alignment = evaluate_against(*groundtruth, moved_to_camera(traj, offset),
                                 moved_to_camera(slam.live_trajectory(), offset), metrics.frame_timestamps(),
                                 slam.loaded_map_alignment(), out_dir, m, sum);
    // What the sensor's depth allows: the same check at the ground truth's poses, moved to the colour camera.
    const auto colour_in_gt_camera = offset ? std::optional<Eigen::Vector3d>(-*offset) : std::nullopt;
    m["sensor"]["long_range_consistency_groundtruth"] =
        metrics.long_range_consistency_at(moved_to_camera(*groundtruth, colour_in_gt_camera), slam.settings().camera);
  } else if (groundtruth) {
    sum.ate_note = fmt::format("not computed: {} tracked pose{} (2 needed)", traj.size(), traj.size() == 1 ? "" : "s");
  }
  if (!sum.ate_note.empty()) m["ate_note"] = sum.ate_note;
  const double share = sum.frames ? static_cast<double>(sum.tracked) / static_cast<double>(sum.frames) : 0.0;
  if (share < options.min_tracked_share)
    sum.failure = fmt::format("tracked {} of {} frames ({:.0f} %, at least {:.0f} % needed): {}", sum.tracked,
                              sum.frames, 100.0 * share, 100.0 * options.min_tracked_share,
                              likely_cause(metrics, settings));
  m["status"] = interrupted ? "interrupted" : sum.failure ? "failed" : "ok";
  if (sum.failure) m["failure"] = *sum.failure;
  sum.metrics = m;
  if (options.save_map) {
    // A map built on a loaded one keeps the loaded map's frame, and so its alignment.
    const auto map_alignment = slam.loaded_map_alignment() ? slam.loaded_map_alignment() : alignment;
    const auto t0 = Clock::now();
    try {
      slam.save_map(*options.save_map, map_alignment);
      std::error_code ec;  // a device (/dev/null) has no size
      const auto bytes = std::filesystem::file_size(*options.save_map, ec);
      m["map_file"] = {{"path", options.save_map->string()},
                       {"bytes", ec ? 0 : bytes},
                       {"save_ms", ms_since(t0)}};
    } catch (const InputError& e) {
      // The run's results are still worth having: metrics and report are written, then the command fails.
      sum.map_error = e.what();
      m["map_file"] = {{"path", options.save_map->string()}, {"error", e.what()}};
    }
  }
  write_file_atomically(out_dir / "metrics.json", m.dump(2) + "\n", "metrics file");
  return sum;
}

}  // namespace varslam::run
