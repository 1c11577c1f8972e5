#include "slam/dense_refinement.hpp"

#include <cmath>
#include <map>
#include <stdexcept>

#include "core/geometry.hpp"
#include "optim/pose_graph.hpp"

namespace varslam::slam {
namespace {

struct Pair {
  std::size_t target, source;
};

std::vector<Pair> candidate_pairs(const std::vector<KeyFramePtr>& kfs, const std::vector<Eigen::Isometry3d>& T_cw,
                                  const DenseRefinementConfig& cfg) {
  std::vector<bool> has_depth;
  for (const KeyFramePtr& kf : kfs) has_depth.push_back(!kf->depth_sample().empty());
  std::vector<Pair> out;
  for (std::size_t a = 0; a < kfs.size(); ++a)
    for (std::size_t b = a + 1; b < kfs.size(); ++b)
      if (kfs[b]->timestamp() - kfs[a]->timestamp() >= cfg.min_gap_s && has_depth[a] && has_depth[b] &&
          views_may_overlap(T_cw[a].inverse(), T_cw[b].inverse(), cfg.max_angle_deg, cfg.max_distance_m))
        out.push_back({a, b});
  return out;
}

}  // namespace

DenseRefinementResult refine_poses_with_depth(const std::vector<KeyFramePtr>& kfs, const PinholeCamera& camera,
                                              std::vector<Eigen::Isometry3d>& T_cw, const DenseRefinementConfig& cfg) {
  if (kfs.size() != T_cw.size()) throw std::invalid_argument("refine_poses_with_depth: one pose per keyframe");
  DenseRefinementResult result;
  const std::vector<Pair> candidates = candidate_pairs(kfs, T_cw, cfg);
  result.candidates = candidates.size();
  const std::size_t n = std::min(candidates.size(), cfg.max_pairs);
  std::map<std::size_t, Surface> surfaces;  // built once per keyframe that takes part
  const auto surface = [&](std::size_t i) -> const Surface& {
    auto it = surfaces.find(i);
    if (it == surfaces.end()) it = surfaces.emplace(i, surface_of(kfs[i]->depth_sample(), camera)).first;
    return it->second;
  };
  optim::PoseGraphProblem pg;
  pg.T_cw = T_cw;
  double moved = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Pair p = candidates[k * candidates.size() / n];
    const Eigen::Isometry3d guess = T_cw[p.target] * T_cw[p.source].inverse();
    const std::optional<DenseAlignment> a = align_surfaces(surface(p.target), surface(p.source), guess);
    if (!a || a->overlap < cfg.min_overlap) continue;
    ++result.aligned;
    const Eigen::Isometry3d change = guess.inverse() * a->T_target_source;
    const double dt = change.translation().norm();
    const double dr = Eigen::AngleAxisd(change.linear()).angle() * 180.0 / M_PI;
    if (dt > cfg.max_correction_m || dr > cfg.max_correction_deg) continue;
    pg.edges.push_back({static_cast<int>(p.target), static_cast<int>(p.source), a->T_target_source, cfg.edge_weight});
    moved += dt;
  }
  result.edges = pg.edges.size();
  if (pg.edges.empty()) return result;
  result.mean_correction_m = moved / static_cast<double>(result.edges);
  pg.fixed.assign(kfs.size(), false);
  for (std::size_t i = 0; i < kfs.size(); ++i) {
    if (i == 0 || kfs[i]->segment() != kfs[i - 1]->segment()) {
      pg.fixed[i] = true;  // a segment's gauge (segments are joined only where a dense edge says how)
      continue;
    }
    pg.edges.push_back({static_cast<int>(i - 1), static_cast<int>(i), T_cw[i - 1] * T_cw[i].inverse(), 1.0});
  }
  optim::PoseGraphConfig pc;
  // The chain's relative poses are good to about 0.3 degrees and 5 mm between neighbouring keyframes.
  pc.rotation_weight = 1.0 / std::pow(0.3 * M_PI / 180.0, 2);
  pc.translation_weight = 1.0 / std::pow(0.005, 2);
  pc.loss = optim::PoseGraphLoss::Huber;
  pc.loss_scale = 3.0;
  pc.max_iterations = 50;
  optim::optimize_pose_graph(pg, pc);
  T_cw = pg.T_cw;
  return result;
}

}  // namespace varslam::slam
