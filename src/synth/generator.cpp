// generate(): lays out the scene for a scenario, renders all frames in parallel and writes the TUM-style folder.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <mutex>
#include <optional>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/boxes_io.hpp"
#include "io/settings.hpp"
#include "synth/camera_path.hpp"
#include "synth/world.hpp"
#include "synth/movers.hpp"
#include "synth/preview.hpp"
#include "synth/renderer.hpp"
#include "synth/scene.hpp"
#include "synth/sensor.hpp"
#include "synth/synth.hpp"

namespace varslam::synth {

std::vector<std::string> scenario_names() {
  return {"static", "walking", "unknown_box", "obstructing_box", "balloon", "mixed", "large_box", "large_box_people"};
}

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMinBoxPixels = 60;  // smaller visible slivers are not labelled (a detector would miss them)

void validate(const SynthConfig& cfg) {
  const auto names = scenario_names();
  if (std::find(names.begin(), names.end(), cfg.scenario) == names.end())
    throw InputError(fmt::format("synth: unknown scenario '{}' (known: {})", cfg.scenario, fmt::join(names, ", ")));
  if (!std::isfinite(cfg.fps) || cfg.fps <= 0 || cfg.fps > 200)
    throw InputError(fmt::format("synth: fps must be in (0, 200], got {}", cfg.fps));
  if (!std::isfinite(cfg.seconds) || cfg.seconds <= 0)
    throw InputError(fmt::format("synth: seconds must be positive, got {}", cfg.seconds));
  if (!std::isfinite(cfg.path_start) || cfg.path_start < 0)
    throw InputError(fmt::format("synth: path start must be >= 0 s, got {}", cfg.path_start));
  if (!(cfg.box_miss_rate >= 0 && cfg.box_miss_rate <= 1))
    throw InputError(fmt::format("synth: box miss rate must be in [0, 1], got {}", cfg.box_miss_rate));
  if (!(cfg.box_jitter_px >= 0) || !std::isfinite(cfg.box_jitter_px))
    throw InputError(fmt::format("synth: box jitter must be >= 0 px, got {}", cfg.box_jitter_px));
}

// Output folder: created, or cleaned if it is an earlier synth output; anything else is refused.
void prepare_dir(const fs::path& dir) {
  if (fs::exists(dir) && !fs::is_directory(dir))
    throw InputError(fmt::format("{}: output path exists and is not a folder", dir.string()));
  if (fs::exists(dir) && !fs::is_empty(dir)) {
    if (!fs::exists(dir / "scenario.json"))
      throw InputError(fmt::format("{}: output folder is not empty and is not an earlier synth output (no "
                                   "scenario.json); synth would mix its files with the ones there: give another --out",
                                   dir.string()));
    fs::remove_all(dir / "rgb");
    fs::remove_all(dir / "depth");
  }
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
}

std::string ts_name(double t) { return fmt::format("{:.6f}", t); }

struct FrameBoxes {
  Detections boxes;
  bool person_visible = false;
};

// Person boxes from the id buffer (visible part only), then detector-like misses and jitter.
FrameBoxes person_boxes(const cv::Mat1b& ids, std::size_t n_people, double ts, const SynthConfig& cfg, SplitMix64& rng,
                        const GaussianTable& gauss) {
  FrameBoxes out;
  if (n_people == 0) return out;
  std::vector<int> x0(n_people, ids.cols), y0(n_people, ids.rows), x1(n_people, -1), y1(n_people, -1);
  std::vector<std::size_t> count(n_people, 0);
  for (int v = 0; v < ids.rows; ++v) {
    const uchar* row = ids.ptr<uchar>(v);
    for (int u = 0; u < ids.cols; ++u) {
      const int k = row[u] - kFirstPersonId;
      if (row[u] < kFirstPersonId || k >= static_cast<int>(n_people)) continue;
      const auto i = static_cast<std::size_t>(k);
      ++count[i];
      x0[i] = std::min(x0[i], u), x1[i] = std::max(x1[i], u), y0[i] = std::min(y0[i], v), y1[i] = std::max(y1[i], v);
    }
  }
  for (std::size_t i = 0; i < n_people; ++i) {
    if (count[i] < kMinBoxPixels) continue;
    out.person_visible = true;
    const double miss = rng.uniform();  // drawn always, so misses do not shift the jitter stream
    if (miss < cfg.box_miss_rate) continue;
    double bx0 = x0[i], by0 = y0[i], bx1 = x1[i] + 1.0, by1 = y1[i] + 1.0;
    if (cfg.box_jitter_px > 0) {
      bx0 += cfg.box_jitter_px * gauss.draw(rng), by0 += cfg.box_jitter_px * gauss.draw(rng);
      bx1 += cfg.box_jitter_px * gauss.draw(rng), by1 += cfg.box_jitter_px * gauss.draw(rng);
    }
    bx0 = std::clamp(bx0, 0.0, static_cast<double>(ids.cols)), bx1 = std::clamp(bx1, 0.0, static_cast<double>(ids.cols));
    by0 = std::clamp(by0, 0.0, static_cast<double>(ids.rows)), by1 = std::clamp(by1, 0.0, static_cast<double>(ids.rows));
    if (bx1 - bx0 < 1 || by1 - by0 < 1) continue;
    Detection d;
    d.timestamp = ts;
    d.label = "person";
    d.score = 1.0f;
    d.box = cv::Rect2f(static_cast<float>(bx0), static_cast<float>(by0), static_cast<float>(bx1 - bx0),
                       static_cast<float>(by1 - by0));
    out.boxes.push_back(d);
  }
  return out;
}

// Mean image motion (pixels) during the exposure, from the poses at its start and end and the rendered depth of
// the static scene (sample points on a mover are skipped, so a mover does not change the blur of the whole image).
cv::Vec2d exposure_motion(const PinholeCamera& cam, const RenderOutput& r, const Eigen::Isometry3d& T_wc,
                          const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b) {
  cv::Vec2d sum(0, 0);
  int n = 0;
  for (int j = 1; j <= 3; ++j)
    for (int i = 1; i <= 3; ++i) {
      const double u = cam.width * i / 4.0, v = cam.height * j / 4.0;
      const int row = static_cast<int>(v), col = static_cast<int>(u);
      const double z = r.depth(row, col);
      if (z <= 0 || r.ids(row, col) != kStaticId) continue;
      const Eigen::Vector3d pw = T_wc * cam.unproject(u, v, z);
      const Eigen::Vector3d pa = T_a.inverse() * pw, pb = T_b.inverse() * pw;
      if (pa.z() <= 0.05 || pb.z() <= 0.05) continue;
      const Eigen::Vector2d d = cam.project(pb) - cam.project(pa);
      sum += cv::Vec2d(d.x(), d.y());
      ++n;
    }
  return n ? sum / n : sum;
}

std::string pose_line(double ts, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.rotation());
  const Eigen::Vector3d p = T.translation();
  return fmt::format("{:.6f} {:.6f} {:.6f} {:.6f} {:.6f} {:.6f} {:.6f} {:.6f}\n", ts, p.x(), p.y(), p.z(), q.x(), q.y(),
                     q.z(), q.w());
}

}  // namespace

World build_world(const SynthConfig& cfg) {
  validate(cfg);
  std::string path_source;
  const Trajectory path = load_camera_path(cfg.path_file, &path_source);

  const std::size_t n_frames = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(cfg.seconds * cfg.fps)));
  const double t_first = path.front().timestamp + cfg.path_start;
  const double span = static_cast<double>(n_frames - 1) / cfg.fps;
  const double path_len = path.back().timestamp - path.front().timestamp;
  if (t_first + span > path.back().timestamp + 1e-6)
    throw InputError(fmt::format("{}: camera path is {:.2f} s long, but {:.2f} s starting at {:.2f} s were requested",
                                 path_source, path_len, cfg.seconds, cfg.path_start));

  World w;
  w.first_timestamp = t_first;
  w.path_source = path_source;
  w.path_length_s = path_len;
  // Path re-expressed relative to its first pose: the camera starts at the origin looking along +z.
  const Eigen::Isometry3d T0_inv = interpolate_pose(path, t_first).inverse();
  w.pose_at = [T0_inv, path, t_first](double t) {
    return Eigen::Isometry3d(T0_inv * interpolate_pose(path, t_first + t));
  };
  const auto& pose_at = w.pose_at;
  std::vector<Eigen::Isometry3d>& poses = w.poses;
  std::vector<double>& stamps = w.stamps;
  poses.resize(n_frames);
  stamps.resize(n_frames);
  for (std::size_t i = 0; i < n_frames; ++i) {
    stamps[i] = t_first + static_cast<double>(i) / cfg.fps;
    poses[i] = pose_at(static_cast<double>(i) / cfg.fps);
  }
  // Where the camera is and looks on average; the room, furniture and movers are laid out around that.
  ViewAnchor anchor;
  Eigen::Vector3d lo = poses[0].translation(), hi = lo, fwd_sum = Eigen::Vector3d::Zero();
  for (const auto& T : poses) {
    anchor.center += T.translation() / static_cast<double>(n_frames);
    lo = lo.cwiseMin(T.translation());
    hi = hi.cwiseMax(T.translation());
    Eigen::Vector3d f = T.rotation().col(2);
    f.y() = 0;
    fwd_sum += f;
  }
  anchor.forward = fwd_sum.norm() > 1e-6 ? fwd_sum.normalized() : Eigen::Vector3d::UnitZ();
  anchor.right = Eigen::Vector3d::UnitY().cross(anchor.forward);
  const double floor_y = hi.y() + 1.35, ceiling_y = lo.y() - 1.4;

  const std::uint64_t seed = cfg.seed;
  // The room is laid out around the movers of every scenario, so it is the same for all of them (a function of
  // path and seed only) and scenarios differ only in the movers shown.
  const Movers all_movers = Movers::plan_all(anchor, floor_y, span, pose_at, mix_seed(seed, 11));
  w.movers = all_movers.select(cfg.scenario);
  Movers& movers = w.movers;

  Eigen::Vector3d room_lo = lo.array() - 1.5, room_hi = hi.array() + 1.5;
  auto enclose = [&](const Eigen::Vector3d& p, double margin) {
    room_lo = room_lo.cwiseMin(Eigen::Vector3d(p.array() - margin));
    room_hi = room_hi.cwiseMax(Eigen::Vector3d(p.array() + margin));
  };
  // Far wall about 4.6 m ahead: most of the view stays within the 5.5 m depth range, as in an office.
  enclose(anchor.center + 4.6 * anchor.forward + 3.0 * anchor.right, 0.0);
  enclose(anchor.center + 4.6 * anchor.forward - 3.0 * anchor.right, 0.0);
  for (const auto& p : all_movers.extent_points()) enclose(p, 0.6);
  room_lo.y() = ceiling_y;
  room_hi.y() = floor_y;

  std::vector<KeepOut> keep = all_movers.keep_outs();
  for (std::size_t i = 0; i < n_frames; i += 5) keep.push_back({{poses[i].translation().x(), poses[i].translation().z()}, 0.6});
  w.scene = build_static_scene(room_lo, room_hi, anchor, keep, mix_seed(seed, 22));
  movers.add_materials(w.scene);
  w.room_lo = room_lo;
  w.room_hi = room_hi;
  return w;
}


SynthSummary generate(const SynthConfig& cfg, const std::filesystem::path& out_dir) {
  const auto wall_start = std::chrono::steady_clock::now();
  World w = build_world(cfg);
  const Scene& scene = w.scene;
  const Movers& movers = w.movers;
  const std::vector<Eigen::Isometry3d>& poses = w.poses;
  const std::vector<double>& stamps = w.stamps;
  const auto& pose_at = w.pose_at;
  const std::size_t n_frames = poses.size();
  const std::uint64_t seed = cfg.seed;
  const Eigen::Vector3d room_lo = w.room_lo, room_hi = w.room_hi;
  const double t_first = w.first_timestamp, path_len = w.path_length_s;
  const std::string& path_source = w.path_source;
  prepare_dir(out_dir);
  PinholeCamera cam;  // fx = fy = 525, cx = 319.5, cy = 239.5, 640x480, bf = 40
  const Renderer renderer(cam);
  const GaussianTable gauss(mix_seed(seed, 44));
  DepthSensorParams dparams;
  dparams.noise = cfg.depth_noise;
  dparams.edge_holes = cfg.depth_edge_holes;
  dparams.max_range_m = cfg.depth_max_m;
  dparams.random_holes = cfg.random_holes_per_frame;
  const RealSensorEffects& real = cfg.real;
  dparams.noise_blur_px = real.depth_noise_blur_px;
  dparams.inverse_depth_step = real.inverse_depth_step;
  dparams.scale = real.depth_scale;
  dparams.dark_dropout = real.dark_dropout;
  const std::optional<LensDistortion> lens =
      real.distorts() ? std::optional<LensDistortion>(std::in_place, cam, real.k1, real.k2, real.k3) : std::nullopt;
  const Eigen::Isometry3d T_colour_depth(Eigen::Translation3d(real.depth_offset_m));
  const double dt_depth = real.depth_time_offset_s;
  std::mt19937_64 drift_rng(mix_seed(seed, 55));
  const double ph1 = std::uniform_real_distribution<double>(0, 2 * M_PI)(drift_rng);
  const double ph2 = std::uniform_real_distribution<double>(0, 2 * M_PI)(drift_rng);

  // Preview frames: about 8, spread over the sequence.
  const std::size_t n_preview = cfg.preview ? std::min<std::size_t>(8, n_frames) : 0;
  std::vector<std::size_t> preview_idx;
  for (std::size_t k = 0; k < n_preview; ++k)
    preview_idx.push_back(n_preview > 1 ? k * (n_frames - 1) / (n_preview - 1) : 0);
  std::vector<PreviewFrame> preview(n_preview);

  std::vector<FrameBoxes> boxes(n_frames);
  // Noisy colour compresses best with Huffman only, depth with run-length encoding (about 2x faster than the
  // default strategy at the same level, and smaller).
  const std::vector<int> png_params{cv::IMWRITE_PNG_COMPRESSION, cfg.png_compression, cv::IMWRITE_PNG_STRATEGY,
                                    cv::IMWRITE_PNG_STRATEGY_HUFFMAN_ONLY};
  const std::vector<int> png_depth_params{cv::IMWRITE_PNG_COMPRESSION, cfg.png_compression, cv::IMWRITE_PNG_STRATEGY,
                                          cv::IMWRITE_PNG_STRATEGY_RLE};
  std::atomic<std::size_t> done{0};
  std::mutex progress_mutex;
  std::exception_ptr failure;
  std::mutex failure_mutex;

  cv::parallel_for_(cv::Range(0, static_cast<int>(n_frames)), [&](const cv::Range& range) {
    RenderOutput r, rd;
    std::vector<Primitive> dynamic;
    for (int fi = range.start; fi < range.end; ++fi) {
      try {
        const auto i = static_cast<std::size_t>(fi);
        const double t = static_cast<double>(i) / cfg.fps;
        SplitMix64 rng(mix_seed(seed, 1000 + i));
        dynamic.clear();
        if (cfg.render_movers) movers.primitives_at(t, dynamic);
        renderer.render(scene, dynamic, poses[i], r);
        if (real.rolling_shutter_s > 0) {
          const double rows = std::max(1, r.color.rows - 1);
          apply_rolling_shutter(r.color, r.depth, cam, poses[i], [&](int row) {
            return pose_at(t + (row / rows - 0.5) * real.rolling_shutter_s);
          });
        }
        // The depth camera: at another instant and from another place when so set, else the colour camera's view.
        const RenderOutput* depth_view = &r;
        if (real.renders_depth_apart()) {
          dynamic.clear();
          if (cfg.render_movers) movers.primitives_at(t + dt_depth, dynamic);
          renderer.render(scene, dynamic, pose_at(t + dt_depth) * T_colour_depth, rd);
          depth_view = &rd;
        }
        cv::Mat1f depth_m = depth_view->depth;
        if (lens) {
          lens->apply(r.color);
          lens->apply(r.ids);
          depth_m = depth_m.clone();
          lens->apply(depth_m);
        }

        if (cfg.motion_blur && cfg.exposure_s > 0) {
          const cv::Vec2d m =
              exposure_motion(cam, r, poses[i], pose_at(t - cfg.exposure_s / 2), pose_at(t + cfg.exposure_s / 2));
          motion_blur(r.color, m[0], m[1]);
        }
        const double gain = 1.0 + cfg.exposure_drift * (0.7 * std::sin(2 * M_PI * t / 23.0 + ph1) +
                                                        0.3 * std::sin(2 * M_PI * t / 7.3 + ph2));
        const cv::Mat3b bgr = sense_color(r.color, gain, cfg.image_noise_sigma, rng, gauss);
        const cv::Mat1w depth = sense_depth(depth_m, dparams, rng, gauss, lens ? &r.color : &depth_view->color);
        boxes[i] = person_boxes(r.ids, movers.people().size(), stamps[i], cfg, rng, gauss);

        write_image_atomically(out_dir / "rgb" / (ts_name(stamps[i]) + ".png"), bgr, "colour image", png_params);
        write_image_atomically(out_dir / "depth" / (ts_name(stamps[i] + dt_depth) + ".png"), depth, "depth image",
                               png_depth_params);
        for (std::size_t k = 0; k < preview_idx.size(); ++k)
          if (preview_idx[k] == i) preview[k] = PreviewFrame{bgr.clone(), depth.clone(), boxes[i].boxes, 5000.0};
        const std::size_t now = ++done;
        if (cfg.progress) {
          std::lock_guard<std::mutex> lock(progress_mutex);
          cfg.progress(now, n_frames);
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        return;
      }
    }
  }, static_cast<double>(n_frames));
  if (failure) std::rethrow_exception(failure);

  // Lists, ground truth, boxes.
  SynthSummary summary;
  summary.frames = n_frames;
  summary.dir = out_dir;
  summary.people = movers.people().size();
  summary.unknown_movers = movers.objects().size();
  {
    std::string rgb = "# color images\n# synthetic sequence: varslam synth --scenario " + cfg.scenario +
                      "\n# timestamp filename\n";
    std::string dep = "# depth maps\n# synthetic sequence: varslam synth --scenario " + cfg.scenario +
                      "\n# timestamp filename\n";
    std::string gt =
        "# ground truth trajectory (camera-to-world, relative to the first pose)\n# timestamp tx ty tz qx qy qz qw\n";
    for (std::size_t i = 0; i < n_frames; ++i) {
      const std::string ts = ts_name(stamps[i]), tsd = ts_name(stamps[i] + dt_depth);
      rgb += ts + " rgb/" + ts + ".png\n";
      dep += tsd + " depth/" + tsd + ".png\n";
      gt += pose_line(stamps[i], poses[i]);
    }
    write_file_atomically(out_dir / "rgb.txt", rgb, "frame list");
    write_file_atomically(out_dir / "depth.txt", dep, "frame list");
    write_file_atomically(out_dir / "groundtruth.txt", gt, "ground truth");
  }
  BoxesByTime by_time;
  for (std::size_t i = 0; i < n_frames; ++i) {
    if (boxes[i].person_visible) ++summary.frames_with_person;
    summary.person_boxes += boxes[i].boxes.size();
    if (!boxes[i].boxes.empty()) by_time[stamps[i]] = boxes[i].boxes;
  }
  write_boxes_file(by_time, out_dir / "boxes.txt");

  Settings settings;
  settings.camera = stated_camera(cam, real);
  settings.fps = cfg.fps;
  settings.depth_factor = 5000.0;
  save_settings(settings, out_dir / "settings.yaml");

  nlohmann::json j;
  j["generator"] = kGeneratorVersion;
  j["scenario"] = cfg.scenario;
  j["seed"] = cfg.seed;
  j["frames"] = n_frames;
  j["fps"] = cfg.fps;
  j["seconds"] = cfg.seconds;
  j["first_timestamp"] = t_first;
  j["path"] = {{"source", path_source}, {"start_s", cfg.path_start}, {"length_s", path_len}};
  j["room"] = {{"min", {room_lo.x(), room_lo.y(), room_lo.z()}}, {"max", {room_hi.x(), room_hi.y(), room_hi.z()}}};
  j["movers"] = movers.describe();
  j["render_movers"] = cfg.render_movers;
  j["static_primitives"] = scene.statics.size();
  j["boxes"] = {{"miss_rate", cfg.box_miss_rate}, {"jitter_px", cfg.box_jitter_px}, {"written", summary.person_boxes},
                {"frames_with_person", summary.frames_with_person}};
  j["sensor"] = {{"depth_noise", cfg.depth_noise ? "0.0012 + 0.0019 (z - 0.4)^2 m" : "off"},
                 {"depth_edge_holes", cfg.depth_edge_holes}, {"depth_max_m", cfg.depth_max_m},
                 {"random_holes_per_frame", cfg.random_holes_per_frame}, {"image_noise_sigma", cfg.image_noise_sigma},
                 {"motion_blur", cfg.motion_blur}, {"exposure_s", cfg.exposure_s}, {"exposure_drift", cfg.exposure_drift},
                 {"real", describe(real)}};
  write_file_atomically(out_dir / "scenario.json", j.dump(2) + "\n", "scenario description");

  if (cfg.preview && !preview.empty())
    write_image_atomically(out_dir / "preview.png", contact_sheet(preview), "preview", png_params);

  summary.seconds_taken = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return summary;
}

}  // namespace varslam::synth
