// The large-movers scenario: a box carried close to the camera covers a quarter to two thirds of the image,
// enters and leaves the view, rests still in the world while held, never reaches the lens, and its episodes vary
// in the ways the benchmark needs (sides, fast and slow exits, holds).
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "synth/large_box.hpp"
#include "synth/movers.hpp"
#include "synth/renderer.hpp"

using namespace varslam;
using namespace varslam::synth;

namespace {

// A hand-held camera walking forward at 0.4 m/s while turning slowly, with a few centimetres of shake.
Eigen::Isometry3d walking_camera(double t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.05 * t, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(0.02 * std::sin(7 * t), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.02 * std::sin(5 * t), 0.01 * std::sin(9 * t), 0.4 * t);
  return T;
}

double box_share(const Movers& movers, const Scene& scene, double t) {
  std::vector<Primitive> dyn;
  movers.primitives_at(t, dyn);
  const Renderer renderer{PinholeCamera{}};
  RenderOutput out;
  renderer.render(scene, dyn, walking_camera(t), out);
  return cv::countNonZero(out.ids >= kFirstObjectId) / (640.0 * 480.0);
}

}  // namespace

TEST(LargeBox, TwentySecondsHoldTwoEpisodesThatCoverMuchOfTheImageAndLeaveIt) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const Movers movers = Movers::script("large_box", ViewAnchor{}, 1.35, 20.0, walking_camera, seed);
    ASSERT_EQ(movers.objects().size(), 1u);
    EXPECT_TRUE(movers.people().empty());
    const ObjectScript& box = movers.objects()[0];
    ASSERT_EQ(box.kind, ObjectScript::Kind::LargeBox);
    ASSERT_EQ(box.large_episodes.size(), 2u);
    EXPECT_LT(box.large_episodes[0].start + box.large_episodes[0].length, box.large_episodes[1].start);
    EXPECT_LE(box.large_episodes[1].start + box.large_episodes[1].length, 20.0);
    Scene scene = build_static_scene({-4, -1.4, -3}, {4, 1.35, 14}, ViewAnchor{}, {}, seed);
    Movers m = movers;
    m.add_materials(scene);
    for (const auto& e : box.large_episodes) {
      EXPECT_GE(e.distance, 0.6);
      EXPECT_LE(e.distance, 1.5);
      // In the middle of the carried part the box covers what the episode was planned to cover, about.
      const double carried_mid = e.start + e.enter_s + e.hold_in_s +
                                 0.5 * (e.length - e.enter_s - e.hold_in_s - e.hold_out_s - e.exit_s);
      const double share = box_share(m, scene, carried_mid);
      EXPECT_GT(share, 0.2) << "seed " << seed << " t " << carried_mid;
      EXPECT_LT(share, 0.75) << "seed " << seed << " t " << carried_mid;
      EXPECT_NEAR(share, e.coverage, 0.2) << "seed " << seed;
      // Out of view when it appears and when it disappears (no popping in or out).
      EXPECT_EQ(box_share(m, scene, e.start), 0.0) << "seed " << seed;
      EXPECT_EQ(box_share(m, scene, e.start + e.length), 0.0) << "seed " << seed;
      Eigen::Isometry3d before;
      EXPECT_FALSE(box.pose_at(e.start - 0.05, before));
    }
  }
}

TEST(LargeBox, AHeldBoxRestsStillInTheWorldAndACarriedOneMovesWithTheCamera) {
  std::mt19937_64 rng(7);
  bool saw_hold = false;
  for (int k = 0; k < 10 && !saw_hold; ++k) {
    for (const auto& e : plan_large_box_episodes(20.0, walking_camera, rng)) {
      if (e.hold_in_s < 0.5) continue;
      saw_hold = true;
      const double a = e.start + e.enter_s + 0.05, b = e.start + e.enter_s + e.hold_in_s - 0.05;
      EXPECT_LT((e.pose_at(a).translation() - e.pose_at(b).translation()).norm(), 1e-9);
      // While carried the camera walks on and the box keeps its distance in front of it.
      const double c = e.start + e.enter_s + e.hold_in_s + 1.5;
      const Eigen::Vector3d in_cam = walking_camera(c).inverse() * e.pose_at(c).translation();
      EXPECT_NEAR(in_cam.z(), e.distance + e.size / 2, 0.35);
    }
  }
  EXPECT_TRUE(saw_hold);
}

TEST(LargeBox, EpisodesVaryInSideSpeedAndHoldsAndNeverTouchTheLens) {
  std::set<int> enter_sides, exit_sides;
  int fast_exits = 0, slow_exits = 0, holds = 0, no_holds = 0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    std::mt19937_64 rng(seed);
    for (const auto& e : plan_large_box_episodes(20.0, walking_camera, rng)) {
      enter_sides.insert(e.enter_side);
      exit_sides.insert(e.exit_side);
      (e.exit_s < 0.9 ? fast_exits : slow_exits)++;
      (e.hold_in_s > 0 || e.hold_out_s > 0 ? holds : no_holds)++;
      EXPECT_GE(e.size, 0.35);
      EXPECT_LE(e.size, 1.3);
      for (double t = e.start; t <= e.start + e.length; t += 0.05) {
        const Eigen::Vector3d c = walking_camera(t).inverse() * e.pose_at(t).translation();
        if (std::abs(c.x()) < e.size) {
          EXPECT_GT(c.z() - e.size / 2, 0.3) << "seed " << seed << " t " << t;
        }
      }
      // Continuous: no jump between track samples beyond what a fast exit moves.
      for (std::size_t i = 1; i < e.track.size(); ++i)
        ASSERT_LT((e.track[i].head<3>() - e.track[i - 1].head<3>()).norm(), 0.1);
    }
  }
  EXPECT_EQ(enter_sides.size(), 2u);
  EXPECT_EQ(exit_sides.size(), 2u);
  EXPECT_GT(fast_exits, 0);
  EXPECT_GT(slow_exits, 0);
  EXPECT_GT(holds, 0);
  EXPECT_GT(no_holds, 0);
}

TEST(LargeBox, ThePeopleVariantAddsTwoWalkersAndLeavesOtherScenariosAlone) {
  const auto still = [](double) { return Eigen::Isometry3d(Eigen::Isometry3d::Identity()); };
  const Movers plan = Movers::plan_all(ViewAnchor{}, 1.35, 20.0, still, 4);
  const Movers with_people = plan.select("large_box_people");
  EXPECT_EQ(with_people.people().size(), 2u);
  ASSERT_EQ(with_people.objects().size(), 1u);
  EXPECT_EQ(with_people.objects()[0].kind, ObjectScript::Kind::LargeBox);
  EXPECT_EQ(with_people.objects()[0].large_episodes.size(), plan.select("large_box").objects()[0].large_episodes.size());
  for (const char* other : {"static", "walking", "unknown_box", "obstructing_box", "balloon", "mixed"}) {
    const Movers selected = plan.select(other);
    for (const auto& o : selected.objects()) EXPECT_NE(o.kind, ObjectScript::Kind::LargeBox) << other;
  }
  // A short sequence gets one episode inside it.
  const Movers short_plan = Movers::script("large_box", ViewAnchor{}, 1.35, 3.0, still, 4);
  ASSERT_EQ(short_plan.objects()[0].large_episodes.size(), 1u);
  const auto& e = short_plan.objects()[0].large_episodes[0];
  EXPECT_GE(e.start, 0.0);
  EXPECT_LE(e.start + e.length, 3.0);
}
