#include "slam/keyframe_localization.hpp"

#include <unordered_set>

#include "optim/pose_optimizer.hpp"
#include "optim/rigid_alignment.hpp"
#include "features/descriptor_matching.hpp"
#include "slam/ba_problem_builder.hpp"
#include "slam/matcher.hpp"

namespace varslam::slam {

int refine_pose_on_matches(Frame& cur, const optim::KernelConfig& kernel) {
  for (auto& mp : cur.map_points)
    if (mp && mp->is_bad()) mp.reset();
  const FramePoseProblem p = frame_pose_problem(cur);
  const std::vector<int>& idx = p.keypoints;
  if (idx.size() < 3) return 0;
  optim::PoseOptimConfig pc;
  pc.kernel = kernel;
  pc.solver = optim::PoseSolver::Dedicated;
  const auto res = optim::optimize_pose(cur.features->camera, cur.T_cw, p.points, p.observations, pc);
  int inliers = 0;
  for (std::size_t k = 0; k < idx.size(); ++k) {
    cur.outlier[idx[k]] = false;
    if (res.outlier[k]) cur.map_points[idx[k]].reset();
    else ++inliers;
  }
  cur.has_pose = true;
  return inliers;
}

namespace {

int clear_matches(Frame& cur) {
  std::fill(cur.map_points.begin(), cur.map_points.end(), nullptr);
  std::fill(cur.outlier.begin(), cur.outlier.end(), false);
  return 0;
}

// Pose from the matches in cur.map_points: rigid 3-D/3-D RANSAC on the ones with depth, then pose-only
// optimisation on all of them. On failure clears the matches and restores the prior pose.
int solve_pose_from_matches(Frame& cur, std::uint64_t seed, const LocalizationConfig& cfg) {
  const Eigen::Isometry3d prior = cur.T_cw;
  const auto fail = [&] {
    cur.T_cw = prior;
    return clear_matches(cur);
  };
  // World points of the matches against the keypoints' own camera-frame points (where depth is valid).
  const FrameFeatures& F = *cur.features;
  std::vector<Eigen::Vector3d> world, camera;
  std::vector<double> tolerance;
  std::vector<int> idx;
  for (std::size_t i = 0; i < cur.map_points.size(); ++i) {
    const MapPointPtr& mp = cur.map_points[i];
    if (!mp || mp->is_bad() || !F.has_depth(i)) continue;
    world.push_back(mp->position());
    camera.push_back(F.unproject(i));
    const double z = F.depth[i];
    tolerance.push_back(cfg.tolerance(z));
    idx.push_back(static_cast<int>(i));
  }
  if (static_cast<int>(world.size()) < cfg.min_inliers) return fail();
  optim::RigidRansacConfig rc;
  rc.iterations = cfg.ransac_iterations;
  rc.min_inliers = cfg.min_inliers;
  rc.seed = seed;
  const optim::RigidRansacResult r = optim::estimate_rigid_ransac(world, camera, rc, &tolerance);
  if (!r.ok) return fail();
  // T_ab maps camera points to world points: it is the camera-to-world pose.
  cur.T_cw = r.T_ab.inverse();
  // Keep only RANSAC inliers among the depth matches; matches without depth stay for the optimiser to judge.
  for (std::size_t k = 0; k < idx.size(); ++k)
    if (!r.inlier[k]) cur.map_points[idx[k]].reset();
  const int inliers = refine_pose_on_matches(cur, cfg.kernel);
  if (inliers < cfg.min_inliers) return fail();
  return inliers;
}

}  // namespace

int locate_against_keyframe(Frame& cur, const KeyFrame& kf, const LocalizationConfig& cfg) {
  std::fill(cur.map_points.begin(), cur.map_points.end(), nullptr);
  if (match_keyframe_by_descriptor(cur, kf) < cfg.min_matches) return clear_matches(cur);
  return solve_pose_from_matches(cur, static_cast<std::uint64_t>(kf.id()) + 1, cfg);
}

KeyframeNeighbourhood keyframe_neighbourhood(const KeyFrame& kf, int covisibles) {
  KeyframeNeighbourhood near;
  std::unordered_set<const MapPoint*> seen;
  const auto add = [&](const KeyFrame& k) {
    for (const auto& mp : k.map_points())
      if (mp && !mp->is_bad() && seen.insert(mp.get()).second) near.points.push_back(mp);
  };
  add(kf);
  near.keyframe_ids.push_back(kf.id());
  for (const auto& n : kf.best_covisibles(static_cast<std::size_t>(covisibles))) {
    if (!n || n->is_bad()) continue;
    add(*n);
    near.keyframe_ids.push_back(n->id());
  }
  return near;
}

int locate_against_points(Frame& cur, const std::vector<MapPointPtr>& points, std::uint64_t seed,
                          const LocalizationConfig& cfg) {
  std::fill(cur.map_points.begin(), cur.map_points.end(), nullptr);
  if (match_points_by_descriptor(cur, points) < cfg.min_matches) return clear_matches(cur);
  return solve_pose_from_matches(cur, seed, cfg);
}

std::optional<Eigen::Isometry3d> locate_points_by_depth(const CameraPoints& camera,
                                                        const std::vector<MapPointPtr>& points, std::uint64_t seed,
                                                        const LocalizationConfig& cfg) {
  const PointDescriptors usable = point_descriptors(points);
  if (usable.points.empty() || camera.descriptors.empty()) return std::nullopt;
  std::vector<Eigen::Vector3d> world, cam;
  std::vector<double> tolerance;
  // Loose, as for a neighbourhood: the points were seen from elsewhere; the RANSAC rejects the wrong matches.
  for (const auto& m : match_descriptors(camera.descriptors, usable.rows, kDescDistHigh, kNeighbourhoodMatchRatio, true)) {
    const auto q = static_cast<std::size_t>(m.query);
    world.push_back(usable.points[static_cast<std::size_t>(m.train)]->position());
    cam.push_back(camera.p_c[q]);
    tolerance.push_back(cfg.tolerance(camera.depth[q]));
  }
  if (static_cast<int>(world.size()) < cfg.min_inliers) return std::nullopt;
  optim::RigidRansacConfig rc;
  rc.iterations = cfg.ransac_iterations;
  rc.min_inliers = 3;
  rc.seed = seed;
  const optim::RigidRansacResult r = optim::estimate_rigid_ransac(world, cam, rc, &tolerance);
  if (!r.ok || r.inliers < cfg.min_inliers) return std::nullopt;
  return r.T_ab.inverse();  // T_ab maps camera points to world points
}

}  // namespace varslam::slam
