// The frames chained while lost: visual odometry between consecutive frames, views spaced by motion, the views'
// points in the newest frame's coordinates, and locating several views together where each alone sees too little.
#include <gtest/gtest.h>

#include "slam/keyframe_localization.hpp"
#include "slam/lost_frame_chain.hpp"
#include "slam/synthetic_map.hpp"

namespace varslam::slam {
namespace {

using synthetic::Keypoint;

/// ~600 world points on a wall 2-3 m ahead, and a camera sliding 2 cm right per frame while turning 0.5 deg.
class LostFrameChainTest : public ::testing::Test {
 protected:
  std::mt19937 rng{5};
  synthetic::World world;

  void SetUp() override {
    const cv::Mat desc = synthetic::random_descriptors(600, rng);
    std::uniform_real_distribution<double> x(-2.0, 2.0), y(-1.2, 1.2), z(2.0, 3.0), mid(-0.5, 0.5);
    // The first 30 near the middle of the view, where every camera of the tests sees them.
    for (int i = 0; i < 600; ++i)
      world.add(i < 30 ? Eigen::Vector3d(mid(rng), mid(rng), z(rng)) : Eigen::Vector3d(x(rng), y(rng), z(rng)),
                desc.row(i));
  }

  static Eigen::Isometry3d pose(int k) {
    return synthetic::pose_cw({0.02 * k, 0.0, 0.0}, synthetic::rotation_deg(0.5 * k, {0, 1, 0}));
  }

  /// The features a camera at T_cw sees: 0.3 px and 0.2 % depth noise, a few flipped bits; `only` (when not empty)
  /// keeps the listed world points and nothing else.
  std::shared_ptr<FrameFeatures> features(const Eigen::Isometry3d& T_cw, const std::vector<int>& only = {}) {
    std::normal_distribution<double> pix(0.0, 0.3), rel(0.0, 0.002);
    std::uniform_int_distribution<int> bits(0, 5);
    std::vector<Keypoint> kps;
    cv::Mat desc;
    for (const auto& s : synthetic::visible_points(world, T_cw)) {
      if (!only.empty() && std::find(only.begin(), only.end(), s.point) == only.end()) continue;
      kps.push_back({s.u + pix(rng), s.v + pix(rng), s.depth * (1.0 + rel(rng)), 1.0f, 0});
      desc.push_back(world.descriptors.row(s.point).clone());
      synthetic::flip_bits(desc.row(desc.rows - 1), bits(rng), rng);
    }
    return synthetic::make_features(kps, desc);
  }
};

TEST_F(LostFrameChainTest, ChainsConsecutiveFramesAndPlacesEachRelativeToTheNewest) {
  LostFrameChain chain;
  for (int k = 0; k < 5; ++k) {
    const auto added = chain.add(static_cast<std::size_t>(10 + k), features(pose(k)));
    EXPECT_EQ(added.chained, k > 0) << "frame " << k;
    EXPECT_TRUE(added.new_view) << "2 cm apart: every frame is a view at the default 1 cm spacing";
  }
  ASSERT_EQ(chain.length(), 5u);
  EXPECT_EQ(chain.views(), 5u);
  const auto placed = chain.placements();
  ASSERT_EQ(placed.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(placed[static_cast<std::size_t>(k)].record, static_cast<std::size_t>(10 + k));
    // T_c_newest of frame k is T_cw(k) * T_wc(4): checked on the pose it gives frame k from the newest's true pose.
    const Eigen::Isometry3d T_cw = placed[static_cast<std::size_t>(k)].T_c_newest * pose(4);
    const auto e = synthetic::pose_error(T_cw, pose(k));
    EXPECT_LT(e.m, 0.005) << "frame " << k;
    EXPECT_LT(e.deg, 0.3) << "frame " << k;
  }
}

TEST_F(LostFrameChainTest, ViewsAreSpacedByMotionAndTheNewestAreKept) {
  LostFrameChainConfig cfg;
  cfg.max_views = 3;
  cfg.view_spacing_m = 0.05;
  cfg.view_spacing_deg = 30.0;
  LostFrameChain chain(cfg);
  int views_added = 0;
  for (int k = 0; k < 12; ++k) views_added += chain.add(static_cast<std::size_t>(k), features(pose(k))).new_view;
  // 2 cm a frame against a 5 cm spacing: frames 0, 3, 6, 9 become views; the three newest are kept.
  EXPECT_EQ(views_added, 4);
  EXPECT_EQ(chain.views(), 3u);
  EXPECT_EQ(chain.length(), 12u);
}

TEST_F(LostFrameChainTest, TheChainStartsAgainWhereAFrameSharesNothingWithTheLast) {
  LostFrameChain chain;
  chain.add(0, features(pose(0)));
  chain.add(1, features(pose(1)));
  // Another place: the same geometry but descriptors that match nothing seen before.
  auto elsewhere = features(pose(2));
  auto stranger = std::make_shared<FrameFeatures>(*elsewhere);
  stranger->descriptors = synthetic::random_descriptors(stranger->descriptors.rows, rng);
  const auto added = chain.add(2, stranger);
  EXPECT_FALSE(added.chained);
  EXPECT_EQ(chain.length(), 1u);
  EXPECT_EQ(chain.placements().front().record, 2u);
}

TEST_F(LostFrameChainTest, ViewPointsAreInTheNewestFramesCoordinates) {
  LostFrameChain chain;
  for (int k = 0; k < 4; ++k) chain.add(static_cast<std::size_t>(k), features(pose(k)));
  const CameraPoints pts = chain.view_points();
  ASSERT_GT(pts.p_c.size(), 1000u);
  ASSERT_EQ(pts.descriptors.rows, static_cast<int>(pts.p_c.size()));
  // Each point lies where a world point is, seen from the newest camera: the nearest world point is within noise.
  int near = 0;
  for (std::size_t i = 0; i < pts.p_c.size(); i += 17) {
    const Eigen::Vector3d p_w = pose(3).inverse() * pts.p_c[i];
    double best = 1e9;
    for (const auto& w : world.points) best = std::min(best, (w - p_w).norm());
    near += best < 0.02;
  }
  EXPECT_EQ(near, static_cast<int>((pts.p_c.size() + 16) / 17));
}

TEST_F(LostFrameChainTest, ViewsTogetherLocateWhereEachAloneSeesTooFewMapPoints) {
  // Map points for world points 0-29 only (the rest of the scene is not in the map). Three views each see 10 of
  // them (and the unmapped scene): with 12 inliers asked, no view alone locates, the three together do.
  std::vector<MapPointPtr> map_points;
  for (int i = 0; i < 30; ++i) {
    auto mp = std::make_shared<MapPoint>(i, world.points[static_cast<std::size_t>(i)], nullptr);
    mp->set_descriptor(world.descriptors.row(i).clone());
    map_points.push_back(mp);
  }
  const auto seen_by = [&](int k) {
    std::vector<int> only;
    for (const auto& s : synthetic::visible_points(world, pose(k)))
      if (s.point >= 30 || s.point % 3 == k / 3) only.push_back(s.point);
    return only;
  };
  LocalizationConfig lc;
  lc.min_inliers = 12;
  lc.ransac_iterations = 2000;
  LostFrameChain chain;
  for (const int k : {0, 3, 6}) {
    chain.add(static_cast<std::size_t>(k), features(pose(k), seen_by(k)));
    LostFrameChain alone;
    alone.add(0, features(pose(k), seen_by(k)));
    EXPECT_FALSE(locate_points_by_depth(alone.view_points(), map_points, 1, lc)) << "view " << k;
  }
  ASSERT_EQ(chain.views(), 3u);
  const auto T_cw = locate_points_by_depth(chain.view_points(), map_points, 1, lc);
  ASSERT_TRUE(T_cw);
  const auto e = synthetic::pose_error(*T_cw, pose(6));
  EXPECT_LT(e.m, 0.02);
  EXPECT_LT(e.deg, 1.0);
}

}  // namespace
}  // namespace varslam::slam
