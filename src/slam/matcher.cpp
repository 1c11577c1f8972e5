#include "slam/matcher.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/geometry.hpp"
#include "features/descriptor_matching.hpp"

namespace varslam::slam {

namespace {

// A map point is matched only where it is seen within 60 deg of its mean viewing direction (descriptors change
// beyond that).
constexpr double kMinViewCos = 0.5;
// Local-map search radius (pixels at level 0, times the level's scale): narrow where the point is seen head-on,
// wider at an angle, where its scale prediction is less sure.
constexpr double kFrontalViewCos = 0.998, kFrontalRadius = 2.5, kObliqueRadius = 4.0;
// Best and second-best candidates at the same scale closer than this ratio: ambiguous, no match.
constexpr double kSameScaleRatio = 0.8;
// Nearest-neighbour ratio of the descriptor matching against a keyframe (Lowe's test).
constexpr double kKeyframeMatchRatio = 0.7;
// Fusion gates on the squared reprojection error at the keypoint's scale, 2 and 3 dof, as ORB-SLAM writes them
// (the 95 % chi-square quantiles 5.991 and 7.815, rounded).
constexpr double kFuseGateMono = 5.99, kFuseGateStereo = 7.8;
// Triangulation matches lie within the 95 % chi-square (1 dof) band of the epipolar line ...
constexpr double kEpipolarGate = 3.84;
// ... and not within 10 pixels (squared, at level 0) of the epipole, where the line says nothing.
constexpr double kMinEpipoleDistance2 = 100.0;

const std::uint8_t* row_ptr(const cv::Mat& m, int r) { return m.ptr<std::uint8_t>(r); }

/// The two closest descriptors to a projected map point among the frame's candidate keypoints, with their levels.
struct CandidateScore {
  int best = std::numeric_limits<int>::max(), second = std::numeric_limits<int>::max();
  int best_idx = -1, best_level = -1, second_level = -1;
};

/// Scores `cands` of `cur` against descriptor `d`, skipping keypoints already matched to a real map point and
/// those whose measured depth disagrees with the predicted virtual right coordinate `ur_pred` by more than `r`.
CandidateScore score_candidates(const Frame& cur, const std::vector<int>& cands, const cv::Mat& d, double ur_pred,
                                double r) {
  const FrameFeatures& F = *cur.features;
  CandidateScore s;
  for (int c : cands) {
    if (cur.map_points[c] && cur.map_points[c]->num_observations() > 0) continue;
    if (F.u_right[c] > 0 && std::abs(ur_pred - F.u_right[c]) > r) continue;
    const int dd = descriptor_distance(d.ptr<std::uint8_t>(), row_ptr(F.descriptors, c));
    if (dd < s.best) {
      s.second = s.best;
      s.second_level = s.best_level;
      s.best = dd;
      s.best_idx = c;
      s.best_level = F.keypoints[c].octave;
    } else if (dd < s.second) {
      s.second = dd;
      s.second_level = F.keypoints[c].octave;
    }
  }
  return s;
}

/// Keeps only matches with a consistent rotation; `rot` collects (keypoint index, angle difference).
void enforce_rotation_consistency(Frame& cur, const std::vector<std::pair<int, float>>& rot, int& n_matches) {
  if (rot.empty()) return;
  std::vector<float> diffs;
  diffs.reserve(rot.size());
  for (const auto& r : rot) diffs.push_back(r.second);
  const std::vector<int> keep = rotation_consistent(diffs);
  std::vector<bool> kept(rot.size(), false);
  for (int k : keep) kept[k] = true;
  // A keypoint can appear twice in `rot` (matched again by a later point): count each removal once.
  for (std::size_t i = 0; i < rot.size(); ++i)
    if (!kept[i] && cur.map_points[rot[i].first]) {
      cur.map_points[rot[i].first].reset();
      --n_matches;
    }
}

}  // namespace

int match_last_frame(Frame& cur, const Frame& last, double radius) {
  const FrameFeatures& F = *cur.features;
  const FrameFeatures& L = *last.features;
  const ScaleInfo& S = *F.scale;
  const Eigen::Isometry3d T_cl = cur.T_cw * last.T_cw.inverse();
  // Moving forward (or back) by more than a baseline shifts the expected pyramid level.
  const double tz = T_cl.inverse().translation().z();
  const double baseline = F.camera.bf / F.camera.fx;
  const bool forward = tz > baseline, backward = -tz > baseline;

  int n = 0;
  std::vector<std::pair<int, float>> rot;
  for (std::size_t i = 0; i < last.map_points.size(); ++i) {
    const MapPointPtr& mp = last.map_points[i];
    if (!mp || last.outlier[i] || mp->is_bad() || mp->moving()) continue;
    const Eigen::Vector3d pc = cur.T_cw * mp->position();
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d uv = F.camera.project(pc);
    if (!F.camera.in_image(uv.x(), uv.y())) continue;
    const int level = L.keypoints[i].octave;
    const double r = radius * S.scale_factors[level];
    std::vector<int> cands;
    if (forward) cands = F.in_area(uv.x(), uv.y(), r, level);
    else if (backward) cands = F.in_area(uv.x(), uv.y(), r, 0, level);
    else cands = F.in_area(uv.x(), uv.y(), r, std::max(0, level - 1), level + 1);
    if (cands.empty()) continue;
    const cv::Mat d = mp->descriptor();
    if (d.empty()) continue;
    const CandidateScore score = score_candidates(cur, cands, d, uv.x() - F.camera.bf / pc.z(), r);
    const int best_idx = score.best_idx;
    if (best_idx >= 0 && score.best <= kDescDistHigh) {
      if (!cur.map_points[best_idx]) ++n;
      cur.map_points[best_idx] = mp;
      cur.outlier[best_idx] = false;
      rot.emplace_back(best_idx, L.keypoints[i].angle - F.keypoints[best_idx].angle);
    }
  }
  enforce_rotation_consistency(cur, rot, n);
  return n;
}

int match_local_map(Frame& cur, const std::vector<MapPointPtr>& points, double radius_scale, LocalMapUse use) {
  const bool tracking = use == LocalMapUse::Tracking;
  const FrameFeatures& F = *cur.features;
  const ScaleInfo& S = *F.scale;
  const Eigen::Isometry3d T_wc = cur.T_cw.inverse();
  const Eigen::Vector3d center = T_wc.translation();
  int n = 0;
  for (const MapPointPtr& mp : points) {
    if (mp->is_bad() || mp->moving() || (tracking && mp->last_seen_frame == cur.id)) continue;
    const Eigen::Vector3d pw = mp->position();
    const Eigen::Vector3d pc = cur.T_cw * pw;
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d uv = F.camera.project(pc);
    if (!F.camera.in_image(uv.x(), uv.y())) continue;
    const Eigen::Vector3d ray = pw - center;
    const double dist = ray.norm();
    if (dist < mp->min_distance() || dist > mp->max_distance()) continue;
    const Eigen::Vector3d nrm = mp->normal();
    const double view_cos = nrm.norm() > 0 ? ray.dot(nrm) / (dist * nrm.norm()) : 1.0;
    if (view_cos < kMinViewCos) continue;
    if (tracking) mp->increase_visible();
    const int level = mp->predict_scale(dist, S.log_scale_factor, S.n_levels);
    const double r =
        radius_scale * (view_cos > kFrontalViewCos ? kFrontalRadius : kObliqueRadius) * S.scale_factors[level];
    const std::vector<int> cands = F.in_area(uv.x(), uv.y(), r, level - 1, level);
    if (cands.empty()) continue;
    const cv::Mat d = mp->descriptor();
    if (d.empty()) continue;
    const auto [best, second, best_idx, best_level, second_level] =
        score_candidates(cur, cands, d, uv.x() - F.camera.bf / pc.z(), r);
    if (best_idx < 0 || best > kDescDistHigh) continue;
    if (best_level == second_level && best > kSameScaleRatio * second) continue;
    if (!cur.map_points[best_idx]) ++n;
    cur.map_points[best_idx] = mp;
    cur.outlier[best_idx] = false;
  }
  return n;
}

int match_keyframe_by_descriptor(Frame& cur, const KeyFrame& kf) {
  const FrameFeatures& K = kf.features();
  const FrameFeatures& F = *cur.features;
  const std::vector<MapPointPtr> kf_points = kf.map_points();
  std::vector<int> rows;
  for (std::size_t i = 0; i < kf_points.size(); ++i)
    if (kf_points[i] && !kf_points[i]->is_bad()) rows.push_back(static_cast<int>(i));
  if (rows.empty() || F.descriptors.empty()) return 0;
  cv::Mat query(static_cast<int>(rows.size()), K.descriptors.cols, K.descriptors.type());
  for (std::size_t r = 0; r < rows.size(); ++r) K.descriptors.row(rows[r]).copyTo(query.row(static_cast<int>(r)));
  const auto matches = match_descriptors(query, F.descriptors, kDescDistLow, kKeyframeMatchRatio, true);
  int n = 0;
  std::vector<std::pair<int, float>> rot;
  for (const auto& m : matches) {
    const int ki = rows[m.query];
    cur.map_points[m.train] = kf_points[ki];
    cur.outlier[m.train] = false;
    ++n;
    rot.emplace_back(m.train, K.keypoints[ki].angle - F.keypoints[m.train].angle);
  }
  enforce_rotation_consistency(cur, rot, n);
  return n;
}

PointDescriptors point_descriptors(const std::vector<MapPointPtr>& points) {
  PointDescriptors d;
  d.points.reserve(points.size());
  for (const MapPointPtr& mp : points)
    if (mp && !mp->is_bad() && !mp->descriptor().empty()) d.points.push_back(mp);
  d.rows.create(static_cast<int>(d.points.size()), kDescriptorBytes, CV_8U);
  for (std::size_t r = 0; r < d.points.size(); ++r) d.points[r]->descriptor().copyTo(d.rows.row(static_cast<int>(r)));
  return d;
}

int match_points_by_descriptor(Frame& cur, const std::vector<MapPointPtr>& points) {
  const FrameFeatures& F = *cur.features;
  const PointDescriptors usable = point_descriptors(points);
  if (usable.points.empty() || F.descriptors.empty()) return 0;
  int n = 0;
  // Loose on purpose: the points were seen from other viewpoints than this frame's, and the rigid RANSAC on depth
  // that follows rejects the wrong matches.
  for (const auto& m : match_descriptors(usable.rows, F.descriptors, kDescDistHigh, kNeighbourhoodMatchRatio, true)) {
    cur.map_points[m.train] = usable.points[m.query];
    cur.outlier[m.train] = false;
    ++n;
  }
  return n;
}

int fuse_into_keyframe(const KeyFramePtr& kf, const std::vector<MapPointPtr>& points, double radius) {
  const FrameFeatures& K = kf->features();
  const ScaleInfo& S = *K.scale;
  const Eigen::Isometry3d T_cw = kf->pose();
  const Eigen::Vector3d center = kf->camera_center();
  int n = 0;
  for (const MapPointPtr& mp : points) {
    if (!mp || mp->is_bad() || mp->index_in(kf.get()) >= 0) continue;
    const Eigen::Vector3d pw = mp->position();
    const Eigen::Vector3d pc = T_cw * pw;
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d uv = K.camera.project(pc);
    if (!K.camera.in_image(uv.x(), uv.y())) continue;
    const Eigen::Vector3d ray = pw - center;
    const double dist = ray.norm();
    if (dist < mp->min_distance() || dist > mp->max_distance()) continue;
    const Eigen::Vector3d nrm = mp->normal();
    if (nrm.norm() > 0 && ray.dot(nrm) < kMinViewCos * dist * nrm.norm()) continue;
    const int level = mp->predict_scale(dist, S.log_scale_factor, S.n_levels);
    const double r = radius * S.scale_factors[level];
    const std::vector<int> cands = K.in_area(uv.x(), uv.y(), r);
    if (cands.empty()) continue;
    const cv::Mat d = mp->descriptor();
    if (d.empty()) continue;
    const double ur_pred = uv.x() - K.camera.bf / pc.z();
    int best = std::numeric_limits<int>::max(), best_idx = -1;
    for (int c : cands) {
      const int kl = K.keypoints[c].octave;
      if (kl < level - 1 || kl > level) continue;
      // Reprojection gate at the keypoint's scale (chi2 2 or 3 dof, 95%).
      const double ex = uv.x() - K.keypoints[c].pt.x, ey = uv.y() - K.keypoints[c].pt.y;
      double e2 = ex * ex + ey * ey;
      double gate = kFuseGateMono;
      if (K.u_right[c] > 0) {
        const double er = ur_pred - K.u_right[c];
        e2 += er * er;
        gate = kFuseGateStereo;
      }
      if (e2 * S.inv_level_sigma2[kl] > gate) continue;
      const int dd = descriptor_distance(d.ptr<std::uint8_t>(), row_ptr(K.descriptors, c));
      if (dd < best) {
        best = dd;
        best_idx = c;
      }
    }
    if (best_idx < 0 || best > kDescDistLow) continue;
    const MapPointPtr existing = kf->map_point(best_idx);
    if (existing && !existing->is_bad()) {
      if (existing->num_observations() > mp->num_observations()) mp->replace_with(existing);
      else existing->replace_with(mp);
    } else {
      mp->add_observation(kf, best_idx, K.has_depth(best_idx));
      kf->add_map_point(mp, best_idx);
    }
    ++n;
  }
  return n;
}

std::vector<std::pair<int, int>> match_for_triangulation(const KeyFrame& kf1, const KeyFrame& kf2) {
  const FrameFeatures& A = kf1.features();
  const FrameFeatures& B = kf2.features();
  const ScaleInfo& S = *A.scale;
  // Fundamental matrix from the relative pose: F = K^-T [t]x R K^-1 (both keyframes share the camera).
  const Eigen::Isometry3d T12 = kf1.pose() * kf2.pose_inverse();
  Eigen::Matrix3d K;
  K << A.camera.fx, 0, A.camera.cx, 0, A.camera.fy, A.camera.cy, 0, 0, 1;
  const Eigen::Matrix3d Kinv = K.inverse();
  const Eigen::Matrix3d F12 = Kinv.transpose() * skew(T12.translation()) * T12.rotation() * Kinv;
  // Epipole of camera 1 in image 2, to skip matches too close to it (poorly conditioned).
  const Eigen::Vector3d c1_in_2 = kf2.pose() * kf1.camera_center();
  const Eigen::Vector2d ep = c1_in_2.z() > 0 ? B.camera.project(c1_in_2) : Eigen::Vector2d(-1e9, -1e9);

  const std::vector<MapPointPtr> mp1 = kf1.map_points(), mp2 = kf2.map_points();
  std::vector<int> free2;
  for (std::size_t j = 0; j < B.size(); ++j)
    if (!mp2[j] && !B.is_close(j)) free2.push_back(static_cast<int>(j));
  std::vector<int> taken(B.size(), -1);
  std::vector<int> taken_dist(B.size(), std::numeric_limits<int>::max());
  std::vector<std::pair<int, int>> pairs;
  for (std::size_t i = 0; i < A.size(); ++i) {
    if (mp1[i] || A.is_close(i)) continue;  // close keypoints already got a point from depth
    const Eigen::Vector3d x1(A.keypoints[i].pt.x, A.keypoints[i].pt.y, 1.0);
    const Eigen::Vector3d line = F12.transpose() * x1;  // epipolar line in image 2
    const double norm2 = line.x() * line.x() + line.y() * line.y();
    if (norm2 < 1e-12) continue;
    int best = kDescDistLow + 1, best_j = -1;
    for (int j : free2) {
      const cv::KeyPoint& kp2 = B.keypoints[j];
      const double dist_line = line.x() * kp2.pt.x + line.y() * kp2.pt.y + line.z();
      if (dist_line * dist_line / norm2 > kEpipolarGate * S.level_sigma2[kp2.octave]) continue;
      const double dx = ep.x() - kp2.pt.x, dy = ep.y() - kp2.pt.y;
      if (dx * dx + dy * dy < kMinEpipoleDistance2 * S.scale_factors[kp2.octave]) continue;
      const int dd = descriptor_distance(row_ptr(A.descriptors, static_cast<int>(i)), row_ptr(B.descriptors, j));
      if (dd < best) {
        best = dd;
        best_j = j;
      }
    }
    if (best_j < 0) continue;
    if (taken[best_j] >= 0) {
      if (best >= taken_dist[best_j]) continue;
      for (auto& p : pairs)
        if (p.second == best_j) p.first = -1;
    }
    taken[best_j] = static_cast<int>(i);
    taken_dist[best_j] = best;
    pairs.emplace_back(static_cast<int>(i), best_j);
  }
  std::erase_if(pairs, [](const auto& p) { return p.first < 0; });
  return pairs;
}

}  // namespace varslam::slam
