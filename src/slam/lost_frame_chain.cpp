#include "slam/lost_frame_chain.hpp"

#include <algorithm>
#include <cmath>

#include "features/descriptor_matching.hpp"
#include "optim/rigid_alignment.hpp"
#include "slam/matcher.hpp"

namespace varslam::slam {

namespace {

constexpr double kOdometryMatchRatio = 0.8;  // consecutive frames look alike: a strict ratio test is affordable
constexpr int kOdometryRansacIterations = 300;

struct DepthKeypoints {
  std::vector<int> index;
  cv::Mat descriptors;
};

DepthKeypoints with_depth(const FrameFeatures& f) {
  DepthKeypoints d;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.has_depth(i)) d.index.push_back(static_cast<int>(i));
  d.descriptors.create(static_cast<int>(d.index.size()), f.descriptors.cols, f.descriptors.type());
  for (std::size_t r = 0; r < d.index.size(); ++r)
    f.descriptors.row(d.index[r]).copyTo(d.descriptors.row(static_cast<int>(r)));
  return d;
}

double turn_deg(const Eigen::Isometry3d& T) { return Eigen::AngleAxisd(T.rotation()).angle() * 180.0 / M_PI; }

}  // namespace

std::optional<Eigen::Isometry3d> relative_pose_by_depth(const FrameFeatures& a, const FrameFeatures& b,
                                                        int min_inliers, std::uint64_t seed) {
  const DepthKeypoints da = with_depth(a), db = with_depth(b);
  if (da.index.empty() || db.index.empty()) return std::nullopt;
  std::vector<Eigen::Vector3d> pa, pb;
  std::vector<double> tolerance;
  for (const auto& m : match_descriptors(db.descriptors, da.descriptors, kDescDistLow, kOdometryMatchRatio, true)) {
    const int ia = da.index[static_cast<std::size_t>(m.train)], ib = db.index[static_cast<std::size_t>(m.query)];
    pa.push_back(a.unproject(static_cast<std::size_t>(ia)));
    pb.push_back(b.unproject(static_cast<std::size_t>(ib)));
    // The depth-dependent tolerance of relocalization (LocalizationConfig), at the farther of the two depths.
    tolerance.push_back(LocalizationConfig{}.tolerance(
        std::max(a.depth[static_cast<std::size_t>(ia)], b.depth[static_cast<std::size_t>(ib)])));
  }
  if (static_cast<int>(pa.size()) < min_inliers) return std::nullopt;
  optim::RigidRansacConfig rc;
  rc.iterations = kOdometryRansacIterations;
  rc.min_inliers = min_inliers;
  rc.seed = seed;
  const optim::RigidRansacResult r = optim::estimate_rigid_ransac(pa, pb, rc, &tolerance);
  if (!r.ok) return std::nullopt;
  return r.T_ab;
}

bool LostFrameChain::is_new_view(const Eigen::Isometry3d& T_anchor_c) const {
  if (views_.empty()) return true;
  const Eigen::Isometry3d rel = links_[views_.back()].T_anchor_c.inverse() * T_anchor_c;
  return rel.translation().norm() >= cfg_.view_spacing_m || turn_deg(rel) >= cfg_.view_spacing_deg;
}

LostFrameChain::Added LostFrameChain::add(std::size_t record, std::shared_ptr<const FrameFeatures> features) {
  Added added;
  if (!features) return added;
  Eigen::Isometry3d T_anchor_c = Eigen::Isometry3d::Identity();
  if (!links_.empty()) {
    const Link& prev = links_.back();
    const auto T_prev_c =
        relative_pose_by_depth(*prev.features, *features, cfg_.min_odometry_inliers, static_cast<std::uint64_t>(record) + 1);
    if (T_prev_c) {
      T_anchor_c = prev.T_anchor_c * *T_prev_c;
      added.chained = true;
    } else {
      clear();
    }
  }
  if (!links_.empty() && links_.size() >= std::max<std::size_t>(cfg_.max_length, 1)) {  // drop the oldest; its view too
    links_.erase(links_.begin());
    std::vector<std::size_t> kept;
    for (const std::size_t v : views_)
      if (v > 0) kept.push_back(v - 1);
    views_ = std::move(kept);
  }
  links_.push_back({record, std::move(features), T_anchor_c});
  if (cfg_.max_views > 0 && is_new_view(T_anchor_c)) {
    views_.push_back(links_.size() - 1);
    if (views_.size() > static_cast<std::size_t>(cfg_.max_views)) views_.erase(views_.begin());
    added.new_view = true;
  }
  release_unused_features();
  return added;
}

void LostFrameChain::release_unused_features() {
  // Placing back needs only the poses; the features are kept for the views and for the next odometry step.
  std::vector<bool> needed(links_.size(), false);
  for (const std::size_t v : views_) needed[v] = true;
  needed.back() = true;
  for (std::size_t i = 0; i < links_.size(); ++i)
    if (!needed[i]) links_[i].features.reset();
}

void LostFrameChain::clear() {
  links_.clear();
  views_.clear();
}

CameraPoints LostFrameChain::view_points() const {
  CameraPoints out;
  if (links_.empty()) return out;
  const Eigen::Isometry3d T_newest_anchor = links_.back().T_anchor_c.inverse();
  std::vector<cv::Mat> rows;
  for (const std::size_t v : views_) {
    const Link& link = links_[v];
    const FrameFeatures& f = *link.features;
    const Eigen::Isometry3d T_newest_c = T_newest_anchor * link.T_anchor_c;
    for (std::size_t i = 0; i < f.size(); ++i) {
      if (!f.has_depth(i)) continue;
      out.p_c.push_back(T_newest_c * f.unproject(i));
      out.depth.push_back(f.depth[i]);
      rows.push_back(f.descriptors.row(static_cast<int>(i)));
    }
  }
  if (!rows.empty()) cv::vconcat(rows, out.descriptors);
  return out;
}

std::vector<LostFrameChain::Placement> LostFrameChain::placements() const {
  std::vector<Placement> out;
  if (links_.empty()) return out;
  const Eigen::Isometry3d& T_anchor_newest = links_.back().T_anchor_c;
  for (const Link& link : links_) out.push_back({link.record, link.T_anchor_c.inverse() * T_anchor_newest});
  return out;
}

}  // namespace varslam::slam
