// The followed mover: when it counts as followed, which keypoints are suspects (search margin) and which are on it
// (marking margin), and how a confirmation moves it.
#include "slam/mover_track.hpp"

#include <gtest/gtest.h>

namespace varslam::slam {
namespace {

Eigen::AlignedBox2f box(float x0, float y0, float x1, float y1) {
  return Eigen::AlignedBox2f(Eigen::Vector2f(x0, y0), Eigen::Vector2f(x1, y1));
}

TEST(MoverTrack, FollowedForMemoryFramesAfterTheLastConfirmation) {
  MoverTrack t({.memory = 30});
  EXPECT_FALSE(t.active(0));
  t.confirm(100, box(200, 100, 400, 300), 0.9f, 1.1f);
  EXPECT_TRUE(t.active(100));
  EXPECT_TRUE(t.active(130));
  EXPECT_FALSE(t.active(131));
  t.confirm(125, box(210, 100, 410, 300), 0.9f, 1.1f);
  EXPECT_TRUE(t.active(155));
  EXPECT_FALSE(t.active(156));
  t.forget();
  EXPECT_FALSE(t.active(126));
  EXPECT_FALSE(t.on_mover({300, 200}, 1.0f));
}

TEST(MoverTrack, MemoryZeroNeverFollowsButStillMarksTheMoverOfTheFrame) {
  MoverTrack t({.memory = 0});
  t.confirm(5, box(200, 100, 400, 300), 0.9f, 1.1f);
  EXPECT_FALSE(t.active(5));
  EXPECT_TRUE(t.on_mover({300, 200}, 1.0f));
}

TEST(MoverTrack, SuspectsLieInTheGrownRegionAndInTheDepthBand) {
  MoverTrack t({.memory = 30, .search_margin_px = 64, .mark_margin_px = 10, .depth_margin = 0.15f});
  t.confirm(1, box(200, 100, 400, 300), 1.0f, 1.2f);
  // Inside, at the mover's depth.
  EXPECT_TRUE(t.suspect({300, 200}, 1.1f));
  EXPECT_TRUE(t.on_mover({300, 200}, 1.1f));
  // 40 px to the right of the region: where a sweeping box is a frame later, a suspect but not yet marked.
  EXPECT_TRUE(t.suspect({440, 200}, 1.1f));
  EXPECT_FALSE(t.on_mover({440, 200}, 1.1f));
  EXPECT_FALSE(t.suspect({470, 200}, 1.1f));
  // The room behind the mover, seen past its edge or through a hole: not the mover.
  EXPECT_FALSE(t.suspect({300, 200}, 4.0f));
  // The band's margin: 15 % on either side.
  EXPECT_TRUE(t.suspect({300, 200}, 0.86f));
  EXPECT_FALSE(t.suspect({300, 200}, 0.84f));
  EXPECT_TRUE(t.suspect({300, 200}, 1.37f));
  EXPECT_FALSE(t.suspect({300, 200}, 1.39f));
  // No depth, no decision.
  EXPECT_FALSE(t.suspect({300, 200}, 0.0f));
}

TEST(MoverTrack, TheDepthBandIsTheMoversAndLeavesAPersonBehindItOut) {
  std::vector<float> depths;
  for (int i = 0; i < 60; ++i) depths.push_back(1.1f + 0.2f * static_cast<float>(i) / 59);  // the box, 1.1-1.3 m
  for (int i = 0; i < 25; ++i) depths.push_back(2.0f + 0.01f * static_cast<float>(i));      // a person at 2 m
  const auto [near, far] = mover_depth_band(depths);
  EXPECT_FLOAT_EQ(near, 1.1f);
  EXPECT_LT(far, 1.7f);
  EXPECT_GE(far, 1.3f);
  // A band no wider than its points.
  const auto [n2, f2] = mover_depth_band({0.9f, 1.0f, 1.05f});
  EXPECT_FLOAT_EQ(n2, 0.9f);
  EXPECT_FLOAT_EQ(f2, 1.05f);
  const auto [n3, f3] = mover_depth_band({});
  EXPECT_EQ(n3, 0.0f);
  EXPECT_EQ(f3, 0.0f);
}

}  // namespace
}  // namespace varslam::slam
