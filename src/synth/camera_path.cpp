#include "synth/camera_path.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>

#include "core/error.hpp"
#include "io/trajectory_io.hpp"

namespace varslam::synth {

namespace {
// TUM RGB-D benchmark, CC BY 4.0 (see the header of the .inc file).
constexpr std::array<double, 8> kBuiltinPath[] = {
#include "synth/builtin_path.inc"
};

StampedPose make_pose(const std::array<double, 8>& r) {
  StampedPose p;
  p.timestamp = r[0];
  p.T_wc.setIdentity();
  p.T_wc.translation() = Eigen::Vector3d(r[1], r[2], r[3]);
  p.T_wc.linear() = Eigen::Quaterniond(r[7], r[4], r[5], r[6]).normalized().toRotationMatrix();
  return p;
}
}  // namespace

Trajectory builtin_camera_path() {
  Trajectory out;
  out.reserve(std::size(kBuiltinPath));
  for (const auto& r : kBuiltinPath) out.push_back(make_pose(r));
  return out;
}

Trajectory load_camera_path(const std::filesystem::path& path_file, std::string* source) {
  if (path_file.empty()) {
    if (source) *source = "built-in (TUM fr2/desk_with_person excerpt, CC BY 4.0)";
    return builtin_camera_path();
  }
  std::filesystem::path file = path_file;
  if (std::filesystem::is_directory(file)) file /= "groundtruth.txt";
  if (!std::filesystem::exists(file)) throw InputError(fmt::format("{}: camera path file not found", file.string()));
  Trajectory path = read_tum_trajectory(file);
  if (path.size() < 2)
    throw InputError(fmt::format("{}: camera path needs at least two poses, found {}", file.string(), path.size()));
  std::stable_sort(path.begin(), path.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.timestamp < b.timestamp; });
  if (source) *source = file.string();
  return path;
}

Eigen::Isometry3d interpolate_pose(const Trajectory& path, double t) {
  if (t <= path.front().timestamp) return path.front().T_wc;
  if (t >= path.back().timestamp) return path.back().T_wc;
  const auto it = std::upper_bound(path.begin(), path.end(), t,
                                   [](double v, const StampedPose& p) { return v < p.timestamp; });
  const StampedPose& b = *it;
  const StampedPose& a = *(it - 1);
  const double span = b.timestamp - a.timestamp;
  const double s = span > 0 ? (t - a.timestamp) / span : 0.0;
  const Eigen::Quaterniond qa(a.T_wc.rotation()), qb(b.T_wc.rotation());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = qa.slerp(s, qb).normalized().toRotationMatrix();
  T.translation() = (1.0 - s) * a.T_wc.translation() + s * b.T_wc.translation();
  return T;
}

}  // namespace varslam::synth
