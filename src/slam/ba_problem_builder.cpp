#include "slam/ba_problem_builder.hpp"

namespace varslam::slam {

optim::Observation keypoint_observation(const FrameFeatures& f, std::size_t i) {
  optim::Observation o;
  o.uv = {f.keypoints[i].pt.x, f.keypoints[i].pt.y};
  o.u_right = f.u_right[i];
  o.inv_sigma2 = f.scale->inv_level_sigma2[f.keypoints[i].octave];
  o.disparity_weight = f.disparity_weight;
  return o;
}

FramePoseProblem frame_pose_problem(const Frame& f) {
  FramePoseProblem p;
  for (std::size_t i = 0; i < f.map_points.size(); ++i) {
    if (!f.map_points[i]) continue;
    p.points.push_back(f.map_points[i]->position());
    p.observations.push_back(keypoint_observation(*f.features, i));
    p.keypoints.push_back(static_cast<int>(i));
  }
  return p;
}

void BaProblemBuilder::add_keyframe(const KeyFramePtr& kf, bool fixed) {
  index_of_[kf->id()] = static_cast<int>(problem.keyframes.size());
  problem.keyframes.push_back({kf->pose(), fixed});
  keyframes.push_back(kf);
}

bool BaProblemBuilder::add_point(const MapPointPtr& mp) {
  const int p = static_cast<int>(problem.points.size());
  bool any = false;
  for (const auto& [kf, idx] : mp->observations()) {
    auto it = index_of_.find(kf->id());
    if (it == index_of_.end() || kf->is_bad()) continue;
    problem.observations.push_back({it->second, p, keypoint_observation(kf->features(), static_cast<std::size_t>(idx))});
    observation_owner.emplace_back(kf, mp);
    any = true;
  }
  if (!any) return false;
  problem.points.push_back(mp->position());
  points.push_back(mp);
  return true;
}

void BaProblemBuilder::write_back() const {
  for (std::size_t i = 0; i < keyframes.size(); ++i)
    if (!problem.keyframes[i].fixed) keyframes[i]->set_pose(problem.keyframes[i].T_cw);
  for (std::size_t p = 0; p < points.size(); ++p) points[p]->set_position(problem.points[p]);
}

int BaProblemBuilder::erase_outliers(const std::vector<bool>& outlier_observation) const {
  int n = 0;
  for (std::size_t o = 0; o < outlier_observation.size(); ++o) {
    if (!outlier_observation[o]) continue;
    const auto& [kf, mp] = observation_owner[o];
    const int idx = mp->index_in(kf.get());
    if (idx >= 0) kf->erase_map_point(idx);
    mp->erase_observation(kf);
    ++n;
  }
  return n;
}

}  // namespace varslam::slam
