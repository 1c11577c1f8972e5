#include "slam/trajectory_guard.hpp"

#include <algorithm>
#include <stdexcept>

namespace varslam::slam {
namespace {

// Where frame i lands with frame j's correction (the world motion from j's live
// pose to j's final pose).
Eigen::Vector3d with_correction_of(const Trajectory& fin, const std::vector<Eigen::Isometry3d>& live, std::size_t j,
                                   std::size_t i) {
  return (fin[j].T_wc * live[j].inverse() * live[i]).translation();
}

// Distance of frame i from the straight path between frames a and b at its
// time.
template <typename PositionOf>
double off_path(const Trajectory& fin, std::size_t a, std::size_t i, std::size_t b, PositionOf at) {
  const double s = (fin[i].timestamp - fin[a].timestamp) / std::max(fin[b].timestamp - fin[a].timestamp, 1e-9);
  return (at(i) - ((1 - s) * at(a) + s * at(b))).norm();
}

}  // namespace

int repair_isolated_poses(Trajectory& fin, const std::vector<Eigen::Isometry3d>& live) {
  if (live.size() != fin.size()) throw std::invalid_argument("repair_isolated_poses: one live pose per final pose");
  int repaired = 0;
  for (std::size_t i = 1; i + 1 < fin.size(); ++i) {
    const std::size_t a = i - 1, b = i + 1;
    if ((fin[i].T_wc.translation() - with_correction_of(fin, live, a, i)).norm() <= kIsolatedCorrection) continue;
    if ((fin[b].T_wc.translation() - with_correction_of(fin, live, a, b)).norm() > kIsolatedCorrection) continue;
    const double final_off = off_path(fin, a, i, b, [&](std::size_t k) { return fin[k].T_wc.translation(); });
    const double live_off =
        off_path(fin, a, i, b, [&](std::size_t k) { return Eigen::Vector3d(live[k].translation()); });
    if (final_off <= kIsolatedCorrection || final_off <= 2 * live_off) continue;
    fin[i].T_wc = fin[a].T_wc * live[a].inverse() * live[i];
    ++repaired;
  }
  return repaired;
}

}  // namespace varslam::slam
