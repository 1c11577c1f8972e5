#include "slam/runner.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <thread>

#include "core/error.hpp"
#include "eval/ate.hpp"
#include "eval/rpe.hpp"
#include "io/colour_registration.hpp"
#include "io/depth_image.hpp"
#include "io/trajectory_io.hpp"
#include "semantic/dynamic_keypoint_masker.hpp"
#include "semantic/filter_stages_image.hpp"

#include <opencv2/imgcodecs.hpp>

namespace varslam::slam {

namespace {
using Clock = std::chrono::steady_clock;

// Raw depth from a separate depth camera (7-Scenes, raw Kinect v1) misfits the colour edges; the settings'
// intrinsics then describe the depth camera. Estimated on up to 10 frames of the first 10 s; when a mapping
// clearly beats identity, depth is warped into the colour camera it implies. Registered data (TUM, Bonn,
// synthetic) comes out as identity and runs unchanged.
nlohmann::json register_depth_if_needed(const Dataset& ds, std::size_t first, std::size_t count, Settings& settings,
                                        SlamConfig& cfg) {
  if (cfg.tracking.depth_rig) return {{"mode", "settings"}};
  if (!cfg.tracking.estimate_registration) return {{"mode", "off"}};
  const auto t0 = Clock::now();
  const std::size_t span = std::min<std::size_t>(count, 300), n = std::min<std::size_t>(span, 10);
  std::vector<cv::Mat> grays, depths;
  for (std::size_t k = 0; k < n; ++k) {
    try {
      RgbdFrame f = ds.load(first + k * span / n);
      grays.push_back(f.gray);
      depths.push_back(f.depth);
    } catch (const InputError&) {
      // an unreadable frame is reported by the run itself; estimate on the others
    }
  }
  const ColourRegistration reg = estimate_colour_registration(grays, depths, settings.camera);
  nlohmann::json j = {{"mode", "auto"}, {"found", reg.found}, {"scale", reg.scale}, {"du", reg.du}, {"dv", reg.dv},
                      {"score", reg.score}, {"identity_score", reg.identity_score}, {"frames", reg.frames},
                      {"ms", std::chrono::duration<double, std::milli>(Clock::now() - t0).count()}};
  if (reg.found) {
    DepthCameraRig rig;
    rig.depth = settings.camera;
    settings.camera = reg.colour_camera(rig.depth);
    cfg.tracking.depth_rig = rig;
    j["colour_camera"] = {{"fx", settings.camera.fx}, {"fy", settings.camera.fy}, {"cx", settings.camera.cx},
                          {"cy", settings.camera.cy}};
    spdlog::info("depth is not registered to colour (edge fit {:.2f} against {:.2f} as given): colour camera fx {:.1f} "
                 "cx {:.1f} cy {:.1f}, depth warped into it (depth.registration: off to keep the images as they are)",
                 reg.score, reg.identity_score, settings.camera.fx, settings.camera.cx, settings.camera.cy);
  }
  return j;
}

const char* state_name(TrackState s) {
  switch (s) {
    case TrackState::NotInitialized: return "not_initialized";
    case TrackState::Ok: return "ok";
    case TrackState::Lost: return "lost";
  }
  return "?";
}

nlohmann::json timing_json(const std::vector<double>& v) {
  const auto [med, p95] = median_p95(v);
  return {{"median_ms", med}, {"p95_ms", p95}, {"count", v.size()}};
}

nlohmann::json count_json(const std::vector<double>& v) {
  const auto [med, p95] = median_p95(v);
  return {{"median", med}, {"p95", p95}, {"frames", v.size()}};
}
}  // namespace

std::pair<double, double> median_p95(std::vector<double> v) {
  if (v.empty()) return {0.0, 0.0};
  std::sort(v.begin(), v.end());
  const double med = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  const std::size_t k = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(v.size()))) - 1;
  return {med, v[std::min(k, v.size() - 1)]};
}

void write_map_ply(const Map& map, const std::filesystem::path& file) {
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

RunSummary run_slam(const Dataset& dataset, const Settings& given_settings, const SlamConfig& given_cfg,
                    const RunOptions& options, const std::filesystem::path& out_dir) {
  std::filesystem::create_directories(out_dir);
  const std::size_t first = std::min(options.first, dataset.size());
  const std::size_t count = std::min(options.max_frames, dataset.size() - first);
  if (count == 0) throw InputError(fmt::format("{}: no frames to process", dataset.root().string()));
  Settings settings = given_settings;
  SlamConfig cfg = given_cfg;
  const nlohmann::json registration = register_depth_if_needed(dataset, first, count, settings, cfg);

  System system(cfg, settings.camera, settings.close_depth_m(), options.mode);

  // Known movers: detector + depth-aware keypoint filter, when the settings ask for one.
  semantic::SemanticSettings sem = semantic::semantic_settings(settings);
  std::unique_ptr<semantic::DynamicKeypointMasker> masker;
  std::vector<double> box_age_ms, det_latency_ms, dropped;
  long frames_without_boxes = 0;
  if (sem.detector.source != "none") {
    if (options.mode == RunMode::Deterministic) sem.asynchronous = false;
    masker = std::make_unique<semantic::DynamicKeypointMasker>(sem);
    system.set_keypoint_filter([&](const RgbdFrame& f, const std::vector<cv::KeyPoint>& kps) {
      semantic::MaskResult r = masker->process(f, kps);
      if (r.have_detections) {
        box_age_ms.push_back(1000.0 * r.staleness_s);
        det_latency_ms.push_back(1000.0 * r.detector_latency_s);
      } else {
        ++frames_without_boxes;
      }
      dropped.push_back(r.stats.dropped);
      if (options.debug_frames.count(f.index)) {
        // The paper's Fig. 3: all keypoints | keypoints in boxes | keypoints kept after the depth test.
        const auto file = out_dir / fmt::format("semantic_stages_{:06d}.png", f.index);
        cv::imwrite(file.string(), semantic::draw_filter_stages(f.bgr, kps, r.boxes, r.keep));
      }
      return r.keep;
    });
    if (sem.mask_extraction)
      system.set_extraction_mask([&](const RgbdFrame& f) { return masker->extraction_mask(f); });
  }

  // Unregistered depth (separate depth camera): warped into the colour camera on the prefetch thread, before
  // any stage reads it.
  std::function<void(RgbdFrame&)> prepare;
  if (cfg.tracking.depth_rig)
    prepare = [rig = *cfg.tracking.depth_rig, colour = settings.camera](RgbdFrame& f) {
      f.depth = register_depth_to_colour(f.depth, rig, colour);
    };
  FramePrefetcher prefetch(dataset, 4, first, count, std::move(prepare));
  std::vector<FrameLog> logs;
  logs.reserve(count);
  Trajectory live;  // poses as tracking gave them, before later corrections
  live.reserve(count);
  const auto t_start = Clock::now();
  std::size_t n = 0;
  double first_stamp = 0;
  auto last_progress = Clock::now();
  for (;;) {
    const auto t_load = Clock::now();
    std::optional<RgbdFrame> frame = prefetch.next();
    const double load_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_load).count();
    if (!frame) break;
    if (n == 0) first_stamp = frame->timestamp;
    if (options.mode == RunMode::RealTime && options.pace) {
      // Feed at the sensor's rate: wait until this frame's time has come.
      const auto due = t_start + std::chrono::duration<double>((frame->timestamp - first_stamp));
      std::this_thread::sleep_until(due);
    }
    const TrackOutcome out = system.process(*frame);
    FrameLog log;
    log.timestamp = frame->timestamp;
    log.state = out.state;
    log.keyframe = out.keyframe;
    log.new_segment = out.new_segment;
    log.keypoints = out.keypoints;
    log.inliers = out.inliers;
    log.depth_edge_rejected = out.depth_edge_rejected;
    log.load_ms = load_ms;
    log.timings = out.timings;
    logs.push_back(log);
    if (out.live_T_wc) live.push_back({frame->timestamp, *out.live_T_wc});
    ++n;
    if (options.progress && (std::chrono::duration<double>(Clock::now() - last_progress).count() > 1.0 || n == count)) {
      last_progress = Clock::now();
      const double el = std::chrono::duration<double>(Clock::now() - t_start).count();
      fmt::print(stderr, "\r[run] frame {}/{}  {:.1f} fps  keyframes {}  points {}  state {}   ", n, count,
                 n / std::max(el, 1e-9), system.map().num_keyframes(), system.map().num_map_points(),
                 state_name(out.state));
    }
  }
  system.finish();
  const double wall = std::chrono::duration<double>(Clock::now() - t_start).count();
  if (options.progress) fmt::print(stderr, "\n");

  RunSummary sum;
  sum.out_dir = out_dir;
  sum.frames = logs.size();
  for (const auto& l : logs) {
    sum.tracked += l.state == TrackState::Ok;
    sum.lost += l.state != TrackState::Ok;
  }
  sum.segments = system.tracker().segments();
  sum.keyframes = system.map().num_keyframes();
  sum.map_points = system.map().num_map_points();
  sum.wall_seconds = wall;
  sum.fps = logs.size() / std::max(wall, 1e-9);

  const Trajectory traj = system.camera_trajectory();
  write_tum_trajectory(traj, out_dir / "CameraTrajectory.txt");
  write_tum_trajectory(system.keyframe_trajectory(), out_dir / "KeyFrameTrajectory.txt");
  write_tum_trajectory(live, out_dir / "LiveTrajectory.txt");
  write_map_ply(system.map(), out_dir / "map.ply");

  std::vector<double> load, extract, filt, match, pose, track, kf_ms, ba_ms, edge_rejected, n_kps;
  for (const auto& l : logs) {
    load.push_back(l.load_ms);
    extract.push_back(l.timings.extract_ms);
    filt.push_back(l.timings.filter_ms);
    match.push_back(l.timings.match_ms);
    pose.push_back(l.timings.pose_ms);
    track.push_back(l.timings.track_ms);
    edge_rejected.push_back(l.depth_edge_rejected);
    n_kps.push_back(l.keypoints);
  }
  const MappingStats ms = system.mapping_stats();
  kf_ms = ms.keyframe_ms;
  nlohmann::json ba_json = nlohmann::json::array();
  for (const auto& b : ms.ba) {
    ba_ms.push_back(b.ms);
    ba_json.push_back({{"keyframe", b.keyframe_id}, {"timestamp", b.timestamp}, {"keyframes", b.keyframes},
                       {"fixed_keyframes", b.fixed_keyframes}, {"points", b.points},
                       {"observations", b.observations}, {"outliers", b.outliers},
                       {"alpha_per_iteration", b.alpha_per_iteration}, {"final_alpha", b.final_alpha}, {"fitted_alpha", b.fitted_alpha}, {"refine_alpha", b.refine_alpha},
                       {"ms", b.ms}});
  }
  nlohmann::json m;
  m["dataset"] = dataset.root().string();
  m["mode"] = options.mode == RunMode::Deterministic ? "deterministic" : "realtime";
  m["frames"] = sum.frames;
  m["tracked_frames"] = sum.tracked;
  m["lost_frames"] = sum.lost;
  m["tracked_share"] = sum.frames ? static_cast<double>(sum.tracked) / sum.frames : 0.0;
  m["map_segments"] = sum.segments;
  m["relocalizations"] = system.tracker().relocalizations();
  m["keyframes"] = sum.keyframes;
  m["map_points"] = sum.map_points;
  m["triangulated_points"] = ms.triangulated_points;
  m["culled_points"] = ms.culled_points;
  m["culled_keyframes"] = ms.culled_keyframes;
  m["wall_seconds"] = wall;
  m["fps"] = sum.fps;
  m["depth_registration"] = registration;
  m["kernels"] = {{"tracking", kernel_name(cfg.tracking.kernel.type)}, {"mapping", kernel_name(cfg.mapping.kernel.type)}};
  m["timings"] = {{"load", timing_json(load)},       {"extract", timing_json(extract)},
                  {"filter", timing_json(filt)},     {"match", timing_json(match)},
                  {"pose_optimization", timing_json(pose)}, {"tracking", timing_json(track)},
                  {"keyframe_processing", timing_json(kf_ms)}, {"local_ba", timing_json(ba_ms)},
                  {"loop_detection", timing_json(system.loop_detection_ms())}};
  m["local_ba"] = ba_json;
  nlohmann::json loops = nlohmann::json::array();
  for (const LoopRecord& l : system.loops())
    loops.push_back({{"keyframe", l.query_keyframe}, {"loop_keyframe", l.loop_keyframe}, {"timestamp", l.timestamp},
                     {"place_score", l.score}, {"ransac_inliers", l.ransac_inliers}, {"inliers", l.inliers},
                     {"fused_points", l.fused_points}, {"correction_m", l.correction_m},
                     {"correction_deg", l.correction_deg}, {"pose_graph_ms", l.pose_graph_ms},
                     {"global_ba_ms", l.global_ba_ms}, {"total_ms", l.total_ms}});
  m["loops"] = loops;
  m["keypoints_per_frame"] = count_json(n_kps);
  m["depth_edge_rejected_per_frame"] = count_json(edge_rejected);
  if (masker) {
    m["semantic"] = {{"detector", masker->detector_name()}, {"detector_runs", masker->detector_runs()},
                     {"asynchronous", sem.asynchronous}, {"frames_without_boxes", frames_without_boxes},
                     {"box_age", timing_json(box_age_ms)}, {"detector_latency", timing_json(det_latency_ms)},
                     {"dropped_keypoints_per_frame", count_json(dropped)}};
  }

  std::optional<std::filesystem::path> gt_path = options.groundtruth ? options.groundtruth : dataset.groundtruth();
  if (gt_path && std::filesystem::exists(*gt_path) && traj.size() >= 2) {
    const Trajectory gt = read_tum_trajectory(*gt_path);
    try {
      const AteResult ate = evaluate_ate(gt, traj);
      sum.ate_rmse = ate.stats.rmse;
      sum.ate_max = ate.stats.max;
      std::vector<double> stamps;
      for (const auto& l : logs) stamps.push_back(l.timestamp);
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
  sum.metrics = m;
  std::ofstream(out_dir / "metrics.json") << m.dump(2) << "\n";
  return sum;
}

}  // namespace varslam::slam
