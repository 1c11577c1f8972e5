#include "viewer/run_replay.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>

#include "core/error.hpp"
#include "io/trajectory_io.hpp"
#include "mapfile/map_file.hpp"
#include "pipeline/slam.hpp"
#include "viewer/viewer_messages.hpp"

namespace varslam::viewer {
namespace fs = std::filesystem;
namespace {

constexpr double kStampTolerance = 1e-3;  // seconds: a trajectory pose belongs to the frame of this stamp

Trajectory read_if_present(const fs::path& file) { return fs::exists(file) ? read_tum_trajectory(file) : Trajectory{}; }

/// The points of the run's ASCII PLY (x y z per vertex, as run::write_map_ply writes them).
std::vector<PointView> read_ply_points(const fs::path& file) {
  std::vector<PointView> pts;
  if (!fs::exists(file)) return pts;
  std::ifstream in(file);
  std::string line;
  std::size_t vertices = 0;
  while (std::getline(in, line) && line != "end_header")
    if (line.rfind("element vertex ", 0) == 0) vertices = std::stoul(line.substr(15));
  if (line != "end_header") throw InputError(fmt::format("{}: not a PLY file (no end_header)", file.string()));
  pts.reserve(vertices);
  for (std::size_t i = 0; i < vertices && std::getline(in, line); ++i) {
    PointView p;
    if (std::sscanf(line.c_str(), "%f %f %f", &p.position.x(), &p.position.y(), &p.position.z()) != 3)
      throw InputError(fmt::format("{}: vertex {} is not 'x y z'", file.string(), i));
    pts.push_back(p);
  }
  return pts;
}

void add_saved_map(MapView& v, const mapfile::SavedMap& m) {
  for (const mapfile::SavedKeyframe& k : m.keyframes) {
    v.keyframes.push_back({k.id, k.T_cw.inverse()});
    for (const auto& [other, weight] : k.connections)
      if (weight >= kDrawnCovisibility && other > k.id) v.covisibility.emplace_back(k.id, other);
    if (k.parent >= 0) v.spanning_tree.emplace_back(k.id, k.parent);
  }
  for (const mapfile::SavedMapPoint& p : m.map_points)
    v.points.push_back({p.position.cast<float>(), static_cast<float>(p.first_keyframe_id), 0.0f});
}

/// The Local BA alphas and closed loops metrics.json recorded, as the live viewer logs them.
std::vector<std::string> logged_events(const fs::path& metrics_file) {
  std::vector<std::string> log;
  if (!fs::exists(metrics_file)) return log;
  std::ifstream in(metrics_file);
  nlohmann::json m;
  try {
    m = nlohmann::json::parse(in);
    for (const auto& ba : m.value("local_ba", nlohmann::json::array()))
      log.push_back(sse_event("alpha", nlohmann::json{{"keyframe", ba.at("keyframe")},
                                                      {"t", ba.at("timestamp")},
                                                      {"alpha", ba.at("final_alpha")},
                                                      {"fitted", ba.at("fitted_alpha")},
                                                      {"refine", ba.at("refine_alpha")},
                                                      {"observations", ba.at("observations")},
                                                      {"outliers", ba.at("outliers")}}
                                           .dump()));
    for (const auto& l : m.value("loops", nlohmann::json::array()))
      log.push_back(sse_event("loop", nlohmann::json{{"query", l.at("keyframe")},
                                                     {"match", l.at("loop_keyframe")},
                                                     {"t", l.at("timestamp")},
                                                     {"inliers", l.at("inliers")},
                                                     {"correction_m", l.at("correction_m")},
                                                     {"correction_deg", l.at("correction_deg")}}
                                          .dump()));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: not the metrics a run writes ({})", metrics_file.string(), e.what()));
  }
  return log;
}

const StampedPose* pose_at(const Trajectory& t, double stamp) {
  auto it = std::lower_bound(t.begin(), t.end(), stamp - kStampTolerance,
                             [](const StampedPose& p, double s) { return p.timestamp < s; });
  return it != t.end() && std::abs(it->timestamp - stamp) <= kStampTolerance ? &*it : nullptr;
}

}  // namespace

std::pair<std::size_t, std::size_t> frames_of_run(const Dataset& dataset, const fs::path& run_dir) {
  const Trajectory t = read_tum_trajectory(run_dir / "CameraTrajectory.txt");
  if (t.empty() || dataset.size() == 0) return {0, 0};
  std::size_t first = dataset.size(), last = 0;
  for (std::size_t i = 0; i < dataset.size(); ++i) {
    const double s = dataset.timestamp(i);
    if (s < t.front().timestamp - kStampTolerance || s > t.back().timestamp + kStampTolerance) continue;
    first = std::min(first, i);
    last = i;
  }
  if (first > last) return {0, 0};
  return {first, last - first + 1};
}

FrameImageSource dataset_images(const Dataset& dataset, std::size_t first, std::size_t count) {
  return [&dataset, first, count](std::size_t i) -> std::optional<std::string> {
    if (i >= count) return std::nullopt;
    try {
      const RgbdFrame f = dataset.load(first + i);
      std::vector<unsigned char> jpeg;
      cv::imencode(".jpg", f.bgr.empty() ? f.gray : f.bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 80});
      return std::string(jpeg.begin(), jpeg.end());
    } catch (const InputError&) {
      return std::nullopt;
    }
  };
}

FinishedRun load_finished_run(const fs::path& run_dir, const Dataset* dataset,
                              const std::optional<fs::path>& map_file) {
  const fs::path traj_file = run_dir / "CameraTrajectory.txt";
  if (!fs::exists(traj_file))
    throw InputError(
        fmt::format("{}: not a run folder (no CameraTrajectory.txt; varslam run -o writes one)", run_dir.string()));
  const Trajectory final_traj = read_tum_trajectory(traj_file);
  const Trajectory live = read_if_present(run_dir / "LiveTrajectory.txt");

  MapView v;
  v.final = true;
  v.final_trajectory = positions(final_traj);
  v.live = positions(live);
  if (map_file) {
    add_saved_map(v, mapfile::load_map_file(*map_file));
  } else {
    v.points = read_ply_points(run_dir / "map.ply");
    long id = 0;
    for (const StampedPose& k : read_if_present(run_dir / "KeyFrameTrajectory.txt"))
      v.keyframes.push_back({id++, k.T_wc});
  }
  if (dataset && dataset->groundtruth() && fs::exists(*dataset->groundtruth()))
    v.groundtruth = groundtruth_in_map_frame(read_tum_trajectory(*dataset->groundtruth()), final_traj);

  // The slider: the dataset's frames in the run's time span, else the trajectory's own poses.
  std::vector<double> stamps;
  int width = 640, height = 480;
  if (dataset) {
    const auto [first, count] = frames_of_run(*dataset, run_dir);
    for (std::size_t i = 0; i < count; ++i) stamps.push_back(dataset->timestamp(first + i));
    if (count > 0) {
      const RgbdFrame f = dataset->load(first);
      width = f.gray.cols;
      height = f.gray.rows;
    }
  } else {
    for (const StampedPose& p : final_traj) stamps.push_back(p.timestamp);
  }
  std::vector<float> poses;
  poses.reserve(stamps.size() * 12);
  for (double s : stamps) {
    const StampedPose* p = pose_at(final_traj, s);
    if (!p) {
      poses.insert(poses.end(), 12, std::numeric_limits<float>::quiet_NaN());
      continue;
    }
    const Eigen::Isometry3d& T = p->T_wc;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) poses.push_back(static_cast<float>(T.linear()(r, c)));
    for (int k = 0; k < 3; ++k) poses.push_back(static_cast<float>(T.translation()[k]));
  }
  FinishedRun run;
  run.frames = stamps.size();
  run.map_points = v.points.size();
  run.keyframes = v.keyframes.size();
  run.greeting = sse_event("hello", nlohmann::json{{"version", std::string(kVersion)},
                                                   {"title", run_dir.string()},
                                                   {"live", false},
                                                   {"frame_count", stamps.size()},
                                                   {"stamps", stamps},
                                                   {"frame_poses", base64(poses.data(), poses.size() * sizeof(float))},
                                                   {"width", width},
                                                   {"height", height},
                                                   {"images", dataset != nullptr}}
                                        .dump());
  run.map = sse_event("map", map_message(v).dump());
  run.log = logged_events(run_dir / "metrics.json");
  return run;
}

}  // namespace varslam::viewer
