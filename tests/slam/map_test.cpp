// Map bookkeeping: observations, covisibility, culling and fusion keep the graph consistent.
#include <gtest/gtest.h>

#include "slam/keyframe.hpp"
#include "slam/map.hpp"

namespace varslam::slam {
namespace {

std::shared_ptr<const ScaleInfo> test_scale() {
  auto s = std::make_shared<ScaleInfo>();
  double f = 1.0;
  for (int l = 0; l < 8; ++l, f *= 1.2) {
    s->scale_factors.push_back(f);
    s->level_sigma2.push_back(f * f);
    s->inv_level_sigma2.push_back(1 / (f * f));
  }
  s->log_scale_factor = std::log(1.2);
  return s;
}

Frame frame_with_points(long id, int n) {
  std::vector<cv::KeyPoint> kps;
  for (int i = 0; i < n; ++i) kps.emplace_back(cv::Point2f(10.0f + 5 * i, 100.0f), 31.0f, 0.0f, 0.0f, 0);
  cv::Mat desc(n, 32, CV_8U, cv::Scalar(0));
  for (int i = 0; i < n; ++i) desc.at<std::uint8_t>(i, 0) = static_cast<std::uint8_t>(i);
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.0f));
  auto f = make_frame_features(kps, desc, depth, PinholeCamera{}, 3.0, test_scale());
  return Frame(id, static_cast<double>(id), f);
}

struct SmallMap {
  Map map;
  std::vector<KeyFramePtr> kfs;
  std::vector<MapPointPtr> points;
};

// Three keyframes that all observe the same 20 points; `connect` builds their covisibility graph.
void build(SmallMap& m, int n_points = 20, bool connect = true) {
  for (int k = 0; k < 3; ++k) m.kfs.push_back(std::make_shared<KeyFrame>(m.map.next_keyframe_id(), frame_with_points(k, n_points)));
  for (int i = 0; i < n_points; ++i) {
    auto mp = std::make_shared<MapPoint>(m.map.next_map_point_id(), Eigen::Vector3d(i * 0.1, 0, 2), m.kfs[0]);
    for (auto& kf : m.kfs) {
      mp->add_observation(kf, i, true);
      kf->add_map_point(mp, i);
    }
    m.points.push_back(mp);
    m.map.add_map_point(mp);
  }
  for (auto& kf : m.kfs) {
    m.map.add_keyframe(kf);
  }
  if (connect)
    for (auto& kf : m.kfs) kf->update_connections();
}

TEST(Map, CovisibilityWeightsCountSharedPoints) {
  SmallMap m;
  build(m);
  EXPECT_EQ(m.kfs[1]->weight(m.kfs[0]), 20);
  EXPECT_EQ(m.kfs[0]->weight(m.kfs[2]), 20);
  EXPECT_EQ(m.kfs[2]->covisibles().size(), 2u);
  EXPECT_EQ(m.kfs[1]->parent(), m.kfs[0]);  // first connection chooses the heaviest, lowest id
  m.map.clear();
}

TEST(Map, ErasingObservationsMakesPointBadAtTwoOrFewer) {
  SmallMap m;
  build(m);
  const MapPointPtr mp = m.points[3];
  EXPECT_EQ(mp->num_observations(), 6);  // depth observations count twice
  mp->erase_observation(m.kfs[2]);
  EXPECT_FALSE(mp->is_bad());
  mp->erase_observation(m.kfs[1]);
  EXPECT_TRUE(mp->is_bad());
  EXPECT_EQ(m.kfs[0]->map_point(3), nullptr);  // a bad point detaches from every keyframe
  m.map.clear();
}

TEST(Map, CulledKeyframeDetachesAndReparentsChildren) {
  SmallMap m;
  build(m);
  m.kfs[2]->change_parent(m.kfs[1]);
  const Eigen::Isometry3d before = m.kfs[2]->pose();
  m.kfs[1]->set_bad();
  EXPECT_TRUE(m.kfs[1]->is_bad());
  EXPECT_EQ(m.kfs[2]->parent(), m.kfs[0]);
  EXPECT_EQ(m.kfs[0]->weight(m.kfs[1]), 0);
  EXPECT_EQ(m.points[0]->index_in(m.kfs[1].get()), -1);
  // A culled keyframe follows its parent: moving the parent moves its resolved pose.
  Eigen::Isometry3d moved = m.kfs[0]->pose();
  moved.translation() += Eigen::Vector3d(1, 0, 0);
  m.kfs[0]->set_pose(moved);
  EXPECT_NEAR((m.kfs[1]->resolved_pose().translation() - before.translation()).norm(), 1.0, 1e-9);
  m.map.clear();
}

// A keyframe reparented twice (loop closing, culling) must not stay a child of its first parent: culling that one
// then handed it back as a child's new parent, here its own parent, and culling it afterwards waited forever on
// its own pose lock.
TEST(Map, CullingAfterReparentingNeverMakesAKeyframeItsOwnParent) {
  SmallMap m;
  build(m);
  m.kfs[1]->change_parent(m.kfs[2]);
  m.kfs[1]->change_parent(m.kfs[0]);
  EXPECT_TRUE(m.kfs[2]->children().empty());
  m.kfs[2]->change_parent(m.kfs[1]);  // kfs[1] was kfs[2]'s child: now it is its parent
  m.kfs[2]->set_bad();
  ASSERT_NE(m.kfs[1]->parent().get(), m.kfs[1].get());
  m.kfs[1]->set_bad();  // returns
  EXPECT_TRUE(m.kfs[1]->is_bad());
  m.kfs[0]->change_parent(m.kfs[0]);
  EXPECT_NE(m.kfs[0]->parent().get(), m.kfs[0].get());
  m.map.clear();
}

// A keyframe connected late (it shared no point when inserted) may already be a newer keyframe's parent; its first
// parent is then the heaviest covisible that does not descend from it, never its own child.
TEST(Map, ALateFirstConnectionNeverChoosesADescendantAsParent) {
  SmallMap m;
  build(m, 20, false);
  for (int i = 0; i < 5; ++i) {  // kfs[0] shares 15 points with the others, kfs[1] and kfs[2] share 20
    m.points[static_cast<std::size_t>(i)]->erase_observation(m.kfs[0]);
    m.kfs[0]->erase_map_point(i);
  }
  m.kfs[2]->update_connections();
  ASSERT_EQ(m.kfs[2]->parent(), m.kfs[1]);
  m.kfs[1]->update_connections();  // its heaviest covisible is its child kfs[2]
  EXPECT_EQ(m.kfs[1]->parent(), m.kfs[0]);
  EXPECT_EQ(m.kfs[2]->parent(), m.kfs[1]);
  EXPECT_EQ(m.kfs[1]->children().count(m.kfs[2]), 1u);
  m.map.clear();
}

// Culled keyframes whose parents point at each other (a spanning tree bent into a cycle): their resolved poses are
// still answered, from where the cycle closes, instead of waiting forever on a lock held up the chain.
TEST(Map, ResolvedPoseOfACycleOfCulledKeyframesReturns) {
  SmallMap m;
  build(m);
  m.kfs[2]->change_parent(m.kfs[1]);
  m.kfs[1]->set_bad();  // kfs[2] is handed to kfs[0]
  m.kfs[2]->set_bad();
  m.kfs[1]->change_parent(m.kfs[2]);
  m.kfs[2]->change_parent(m.kfs[1]);
  ASSERT_EQ(m.kfs[1]->parent(), m.kfs[2]);
  ASSERT_EQ(m.kfs[2]->parent(), m.kfs[1]);
  EXPECT_TRUE(m.kfs[1]->resolved_pose().matrix().allFinite());
  EXPECT_TRUE(m.kfs[2]->resolved_pose().matrix().allFinite());
  m.map.clear();
}

TEST(Map, ReplaceMovesObservationsToSurvivor) {
  SmallMap m;
  build(m);
  auto dup = std::make_shared<MapPoint>(m.map.next_map_point_id(), Eigen::Vector3d(5, 5, 5), m.kfs[0]);
  // dup is observed only in a keypoint that no other point uses in kf 0 (reuse index 0 after freeing it).
  m.points[0]->erase_observation(m.kfs[0]);
  m.kfs[0]->erase_map_point(0);
  dup->add_observation(m.kfs[0], 0, true);
  m.kfs[0]->add_map_point(dup, 0);
  dup->replace_with(m.points[0]);
  EXPECT_TRUE(dup->is_bad());
  EXPECT_EQ(dup->replaced_by(), m.points[0]);
  EXPECT_EQ(m.kfs[0]->map_point(0), m.points[0]);
  EXPECT_EQ(m.points[0]->index_in(m.kfs[0].get()), 0);
  m.map.clear();
}

TEST(Frame, GridSearchFindsKeypointsInRadiusAndLevel) {
  const Frame f = frame_with_points(0, 20);
  const auto hits = f.features->in_area(30.0, 100.0, 6.0);
  // Keypoints at x = 25, 30, 35 lie within 6 px of (30, 100).
  EXPECT_EQ(hits.size(), 3u);
  EXPECT_TRUE(f.features->in_area(30.0, 100.0, 6.0, 1, 2).empty());
  EXPECT_NEAR(f.features->u_right[0], 10.0 - 40.0 / 2.0, 1e-5);
}

}  // namespace
}  // namespace varslam::slam

namespace varslam::slam {
namespace {

TEST(Frame, DepthEdgeTestFlagsDiscontinuitiesOnly) {
  cv::Mat depth(40, 40, CV_32F, cv::Scalar(4.0f));
  depth(cv::Rect(0, 0, 20, 40)).setTo(1.5f);  // a person at 1.5 m in front of a wall at 4 m
  EXPECT_TRUE(on_depth_edge(depth, 20, 20, 4.0f, 0.1));   // right at the boundary
  EXPECT_TRUE(on_depth_edge(depth, 19, 20, 1.5f, 0.1));
  EXPECT_FALSE(on_depth_edge(depth, 30, 20, 4.0f, 0.1));  // inside the wall
  EXPECT_FALSE(on_depth_edge(depth, 5, 20, 1.5f, 0.1));   // inside the person
  depth.at<float>(30, 30) = 0.0f;                          // holes do not count as an edge
  EXPECT_FALSE(on_depth_edge(depth, 31, 30, 4.0f, 0.1));
}

// The motion-model cross-check compares frames by established inliers: map points (not temporary ones) found in
// enough frames, and not flagged as outliers in this frame.
TEST(Map, EstablishedCountSkipsYoungTemporaryAndOutlierPoints) {
  SmallMap m;
  build(m, 6);
  Frame f = frame_with_points(10, 6);
  for (int i = 0; i < 5; ++i) f.map_points[i] = m.points[i];
  m.points[0]->increase_found(3);  // found 4 times (counters start at 1)
  m.points[1]->increase_found(3);
  m.points[2]->increase_found(3);
  f.outlier[2] = true;             // established but an outlier here
  m.points[3]->increase_found(1);  // found twice: young
  auto temporary = std::make_shared<MapPoint>(-1, Eigen::Vector3d(0, 0, 2), nullptr);
  temporary->increase_found(10);   // no observation: a depth point of the last frame, never established
  f.map_points[5] = temporary;
  EXPECT_EQ(f.num_established(3), 2);
  EXPECT_EQ(f.num_established(2), 3);
  EXPECT_EQ(f.num_established(5), 0);
  m.map.clear();
}

}  // namespace
}  // namespace varslam::slam
