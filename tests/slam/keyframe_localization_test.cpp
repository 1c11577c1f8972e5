// Locating a frame against one keyframe with no pose prior: the pose comes out right despite corrupted depths and
// clutter, and a frame of another place (or with inconsistent geometry) is refused without side effects.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "slam/keyframe_localization.hpp"
#include "slam/map.hpp"
#include "slam/synthetic_map.hpp"

namespace varslam::slam {
namespace {

using synthetic::Keypoint;

/// What the frame's keypoint i is: a view of world point `point` (-1: clutter), with its depth corrupted or not.
struct KeypointTruth {
  int point = -1;
  bool bad_depth = false, no_depth = false;
};

/// A keyframe at a known pose with map points for ~400 world points on three tilted planes 1-4 m ahead, and a
/// frame 0.7 m / ~30 deg away that sees most of them.
class KeyframeLocalization : public ::testing::Test {
 protected:
  std::mt19937 rng{11};
  synthetic::World world;
  Map map;
  KeyFramePtr kf;
  std::vector<MapPointPtr> point_of;  // per world point
  Eigen::Isometry3d T_kf = synthetic::pose_cw({0.3, -0.1, 0.2}, synthetic::rotation_deg(10, {0, 1, 0}));
  Eigen::Isometry3d T_true;  // the frame's pose

  void SetUp() override {
    build_world(400);
    build_keyframe();
    // The frame: 0.6 m to the right, 0.3 m forward, turned back toward the scene and rolled.
    const Eigen::Isometry3d T_wk = T_kf.inverse();
    const Eigen::Vector3d center = T_wk * Eigen::Vector3d(0.6, 0.1, 0.3);
    const Eigen::Matrix3d R = T_wk.linear() * synthetic::rotation_deg(-16, {0, 1, 0}) *
                              synthetic::rotation_deg(6, {1, 0, 0}) * synthetic::rotation_deg(22, {0, 0, 1});
    T_true = synthetic::pose_cw(center, R);
  }
  void TearDown() override { map.clear(); }

  void build_world(int n) {
    const PinholeCamera cam;
    std::uniform_real_distribution<double> u(8, cam.width - 8), v(8, cam.height - 8);
    std::uniform_int_distribution<int> plane(0, 2);
    const double dist[] = {1.3, 2.2, 3.0}, a[] = {0.3, -0.25, 0.1}, b[] = {0.1, 0.2, -0.3};
    const cv::Mat desc = synthetic::random_descriptors(n, rng);
    const Eigen::Isometry3d T_wk = T_kf.inverse();
    for (int i = 0; i < n; ++i) {
      const double x = u(rng), y = v(rng);
      const int p = plane(rng);
      // Ray (xn, yn, 1) meets the plane a*x + b*y + z = d at z = d / (a xn + b yn + 1).
      const double xn = (x - cam.cx) / cam.fx, yn = (y - cam.cy) / cam.fy;
      const double z = dist[p] / (a[p] * xn + b[p] * yn + 1.0);
      world.add(T_wk * cam.unproject(x, y, z), desc.row(i));
    }
  }

  void build_keyframe() {
    const auto seen = synthetic::visible_points(world, T_kf);
    std::vector<Keypoint> kps;
    cv::Mat desc;
    std::normal_distribution<double> pix(0.0, 0.3);
    std::uniform_int_distribution<int> bits(0, 5);
    for (const auto& s : seen) {
      kps.push_back({s.u + pix(rng), s.v + pix(rng), s.depth, 1.0f, 0});
      desc.push_back(world.descriptors.row(s.point).clone());
      synthetic::flip_bits(desc.row(desc.rows - 1), bits(rng), rng);
    }
    Frame f(0, 0.0, synthetic::make_features(kps, desc));
    f.T_cw = T_kf;
    kf = std::make_shared<KeyFrame>(map.next_keyframe_id(), f);
    map.add_keyframe(kf);
    point_of.assign(world.points.size(), nullptr);
    for (std::size_t i = 0; i < seen.size(); ++i) {
      auto mp = std::make_shared<MapPoint>(map.next_map_point_id(), world.points[seen[i].point], kf);
      mp->add_observation(kf, static_cast<int>(i), true);
      kf->add_map_point(mp, static_cast<int>(i));
      mp->compute_descriptor();
      mp->update_normal_and_depth(kf->features().scale->scale_factors);
      map.add_map_point(mp);
      point_of[seen[i].point] = mp;
    }
  }

  /// The frame's features: the points it sees (a few flipped bits, 0.3 px noise, depth noise 0.2%), a fraction
  /// `bad_depth` of them with a grossly wrong depth, 10% with none, plus `clutter` unrelated keypoints.
  std::shared_ptr<FrameFeatures> frame_features(double bad_depth, int clutter, std::vector<KeypointTruth>& truth) {
    const auto seen = synthetic::visible_points(world, T_true);
    std::normal_distribution<double> pix(0.0, 0.3), rel(0.0, 0.002);
    std::uniform_real_distribution<double> unit(0, 1), far(1.6, 2.5), near(0.3, 0.6), px(10, 600), py(10, 460),
        depth(0.8, 5.0);
    std::uniform_int_distribution<int> bits(0, 5);
    std::vector<Keypoint> kps;
    cv::Mat desc;
    truth.clear();
    for (const auto& s : seen) {
      KeypointTruth t{s.point};
      double d = s.depth * (1.0 + rel(rng));
      const double r = unit(rng);
      if (r < bad_depth) {
        d = s.depth * (unit(rng) < 0.5 ? far(rng) : near(rng));
        t.bad_depth = true;
      } else if (r < bad_depth + 0.1) {
        d = -1;
        t.no_depth = true;
      }
      kps.push_back({s.u + pix(rng), s.v + pix(rng), d, 1.0f, 0});
      desc.push_back(world.descriptors.row(s.point).clone());
      synthetic::flip_bits(desc.row(desc.rows - 1), bits(rng), rng);
      truth.push_back(t);
    }
    desc.push_back(synthetic::random_descriptors(clutter, rng));
    for (int i = 0; i < clutter; ++i) {
      kps.push_back({px(rng), py(rng), depth(rng), 1.0f, 0});
      truth.push_back({});
    }
    return synthetic::make_features(kps, desc);
  }
};

TEST_F(KeyframeLocalization, SetupIsAFarApartViewOfTheSameScene) {
  const auto e = synthetic::pose_error(T_true, T_kf);
  EXPECT_GT(e.m, 0.5);
  EXPECT_LT(e.m, 1.0);
  EXPECT_GT(e.deg, 20.0);
  EXPECT_LT(e.deg, 40.0);
  EXPECT_GT(kf->tracked_map_points(0), 300);
  EXPECT_GT(synthetic::visible_points(world, T_true).size(), 200u);
}

TEST_F(KeyframeLocalization, RecoversPoseWithoutPriorDespiteBadDepthsAndClutter) {
  std::vector<KeypointTruth> truth;
  Frame cur(5, 0.0, frame_features(0.3, 80, truth));
  ASSERT_TRUE(cur.T_cw.isApprox(Eigen::Isometry3d::Identity()));

  const int inliers = locate_against_keyframe(cur, *kf, LocalizationConfig{});

  const auto e = synthetic::pose_error(cur.T_cw, T_true);
  EXPECT_LT(e.m, 0.01);
  EXPECT_LT(e.deg, 0.5);
  EXPECT_TRUE(cur.has_pose);
  int good = 0, bad_depth_kept = 0, matched = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (truth[i].point >= 0 && !truth[i].bad_depth && point_of[truth[i].point]) ++good;
    if (!cur.map_points[i]) continue;
    ++matched;
    EXPECT_FALSE(cur.outlier[i]);
    // Every kept match is the keypoint's own world point (never clutter, never another point).
    ASSERT_GE(truth[i].point, 0) << "clutter keypoint " << i << " matched";
    EXPECT_EQ(cur.map_points[i], point_of[truth[i].point]) << "keypoint " << i;
    if (truth[i].bad_depth) ++bad_depth_kept;
  }
  EXPECT_EQ(inliers, matched);
  // Nearly every keypoint with a sound (or no) depth is kept; corrupted depths are rejected.
  EXPECT_GE(inliers, static_cast<int>(0.85 * good));
  EXPECT_LE(bad_depth_kept, 3);
}

TEST_F(KeyframeLocalization, FrameOfAnotherPlaceIsRefusedUntouched) {
  std::vector<KeypointTruth> truth;
  auto f = frame_features(0.0, 0, truth);
  f->descriptors = synthetic::random_descriptors(f->descriptors.rows, rng);  // same geometry, other place
  Frame cur(5, 0.0, f);
  const Eigen::Isometry3d prior = synthetic::pose_cw({1, 2, 3}, synthetic::rotation_deg(40, {1, 1, 0}));
  cur.T_cw = prior;

  EXPECT_EQ(locate_against_keyframe(cur, *kf, LocalizationConfig{}), 0);
  EXPECT_TRUE(cur.T_cw.isApprox(prior));
  EXPECT_TRUE(std::none_of(cur.map_points.begin(), cur.map_points.end(), [](const auto& p) { return p != nullptr; }));
}

TEST_F(KeyframeLocalization, MatchingDescriptorsWithInconsistentGeometryAreRefused) {
  std::vector<KeypointTruth> truth;
  auto f = frame_features(0.0, 0, truth);
  // Same descriptors, but the keypoints' positions and depths are dealt out at random: no rigid motion fits.
  std::vector<std::size_t> order(f->size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<Keypoint> shuffled;
  for (std::size_t i = 0; i < f->size(); ++i)
    shuffled.push_back({f->keypoints[order[i]].pt.x, f->keypoints[order[i]].pt.y, f->depth[order[i]], 1.0f, 0});
  Frame cur(5, 0.0, synthetic::make_features(shuffled, f->descriptors));
  const Eigen::Isometry3d prior = cur.T_cw;

  EXPECT_EQ(locate_against_keyframe(cur, *kf, LocalizationConfig{}), 0);
  EXPECT_TRUE(cur.T_cw.isApprox(prior));
  EXPECT_TRUE(std::none_of(cur.map_points.begin(), cur.map_points.end(), [](const auto& p) { return p != nullptr; }));
}

TEST_F(KeyframeLocalization, RefinePoseDropsWrongMatchesAndConverges) {
  std::vector<KeypointTruth> truth;
  Frame cur(5, 0.0, frame_features(0.0, 0, truth));
  int right = 0;
  for (std::size_t i = 0; i < truth.size(); ++i)
    if (truth[i].point >= 0 && point_of[truth[i].point]) {
      cur.map_points[i] = point_of[truth[i].point];
      ++right;
    }
  // Every tenth match points to another (far away in the image) map point.
  std::vector<std::size_t> wrong;
  for (std::size_t i = 0; i < truth.size(); i += 10)
    if (cur.map_points[i]) wrong.push_back(i);
  for (std::size_t k = 0; k < wrong.size(); ++k) cur.map_points[wrong[k]] = cur.map_points[wrong[(k + wrong.size() / 2) % wrong.size()]];
  // Start 5 cm and 2 deg off.
  Eigen::Isometry3d start = T_true;
  start.translation() += Eigen::Vector3d(0.03, -0.03, 0.03);
  start.linear() = synthetic::rotation_deg(2, {1, 2, 0}) * start.linear();
  cur.T_cw = start;

  const int inliers = refine_pose_on_matches(cur, optim::KernelConfig{});

  const auto e = synthetic::pose_error(cur.T_cw, T_true);
  EXPECT_LT(e.m, 0.01);
  EXPECT_LT(e.deg, 0.5);
  for (std::size_t i : wrong) EXPECT_EQ(cur.map_points[i], nullptr) << "wrong match " << i << " kept";
  EXPECT_GE(inliers, static_cast<int>(0.95 * (right - static_cast<int>(wrong.size()))));
  EXPECT_LE(inliers, right - static_cast<int>(wrong.size()));
}

}  // namespace
}  // namespace varslam::slam
