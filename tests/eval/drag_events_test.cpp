// Dragged events on constructed live trajectories: a jump, a slow drift, two separate drags, a short trajectory.
#include <gtest/gtest.h>

#include "eval/drag_events.hpp"
#include "eval_test_util.hpp"

namespace varslam {
namespace {

// Ground truth at 30 Hz over [0, 10] s moving along x at 0.2 m/s; the live estimate is ground truth plus
// offset(t) along y.
template <class Offset>
void make(Trajectory& gt, Trajectory& live, Offset offset) {
  for (int k = 0; k <= 300; ++k) {
    const double t = k / 30.0;
    gt.push_back({t, test::pose({0.2 * t, 0, 0})});
    live.push_back({t, test::pose({0.2 * t, offset(t), 0})});
  }
}

TEST(DragEvents, ATrackedLiveTrajectoryHasNone) {
  Trajectory gt, live;
  make(gt, live, [](double) { return 0.0; });
  EXPECT_TRUE(find_drag_events(gt, live).empty());
}

TEST(DragEvents, AJumpThatStaysIsOneEventAtItsTime) {
  Trajectory gt, live;
  // The pose is pulled 30 cm sideways over 0.2 s at t = 4 s and stays there.
  make(gt, live, [](double t) { return t < 4.0 ? 0.0 : t < 4.2 ? 1.5 * (t - 4.0) : 0.3; });
  const auto events = find_drag_events(gt, live);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_GT(events[0].start, 2.9);
  EXPECT_LT(events[0].end, 5.3);
  EXPECT_NEAR(events[0].peak_m, 0.3, 0.01);
}

TEST(DragEvents, ASlowDriftBelowTheThresholdPerSecondIsNotADrag) {
  Trajectory gt, live;
  // 5 cm per second: 50 cm after 10 s, but never 10 cm within one second.
  make(gt, live, [](double t) { return 0.05 * t; });
  EXPECT_TRUE(find_drag_events(gt, live).empty());
  DragOptions strict;
  strict.threshold_m = 0.04;
  EXPECT_EQ(find_drag_events(gt, live, strict).size(), 1u);
}

TEST(DragEvents, AnErrorDippingBelowTheThresholdWithinTheWindowIsStillOneEvent) {
  Trajectory gt, live;
  // Pulled 15 cm at 4 s, 15 cm back at 4.5 s: the one-second windows around both overlap.
  make(gt, live, [](double t) { return t >= 4.0 && t < 4.5 ? 0.15 : 0.0; });
  EXPECT_EQ(find_drag_events(gt, live).size(), 1u);
}

TEST(DragEvents, TwoSeparateDragsAreTwoEvents) {
  Trajectory gt, live;
  // Pulled away at 2 s, back (a recovery is also a jump) at 5 s, pulled again at 8 s.
  make(gt, live, [](double t) { return (t >= 2.0 && t < 5.0) || t >= 8.0 ? 0.5 : 0.0; });
  EXPECT_EQ(find_drag_events(gt, live).size(), 3u);
}

TEST(DragEvents, ATrajectoryShorterThanTheWindowHasNone) {
  Trajectory gt, live;
  for (int k = 0; k < 10; ++k) {
    gt.push_back({k / 30.0, test::pose({0, 0, 0})});
    live.push_back({k / 30.0, test::pose({k * 0.5, 0, 0})});
  }
  EXPECT_TRUE(find_drag_events(gt, live).empty());
}

}  // namespace
}  // namespace varslam
