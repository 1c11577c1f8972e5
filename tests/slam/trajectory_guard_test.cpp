// The final trajectory's last check: a lone pose an optimisation misplaced is
// replaced; a bad live pose that Local BA set right is kept; corrections shared
// by neighbours (BA, loop bends) are never touched.
#include "slam/trajectory_guard.hpp"

#include <gtest/gtest.h>

namespace varslam::slam {
namespace {

struct Case {
  Trajectory final_poses;
  std::vector<Eigen::Isometry3d> live;
};

// Ten frames along x at 1 cm per frame; every final pose is its live pose moved
// by a common correction (a BA shift of 3 cm in y).
Case straight_run() {
  Case c;
  for (int i = 0; i < 10; ++i) {
    Eigen::Isometry3d live = Eigen::Isometry3d::Identity();
    live.translation() = Eigen::Vector3d(0.01 * i, 0, 1);
    StampedPose p{0.033 * i, live};
    p.T_wc.translation().y() += 0.03;
    c.final_poses.push_back(p);
    c.live.push_back(live);
  }
  return c;
}

TEST(TrajectoryGuard, CommonCorrectionsAreKept) {
  Case c = straight_run();
  const Trajectory before = c.final_poses;
  EXPECT_EQ(repair_isolated_poses(c.final_poses, c.live), 0);
  for (std::size_t i = 0; i < before.size(); ++i) EXPECT_TRUE(c.final_poses[i].T_wc.isApprox(before[i].T_wc));
}

TEST(TrajectoryGuard, ALoneMisplacedPoseTakesItsNeighboursCorrection) {
  Case c = straight_run();
  c.final_poses[5].T_wc.translation() += Eigen::Vector3d(0.3, 1.0, -1.4);  // 1.7 m off, live pose fine
  EXPECT_EQ(repair_isolated_poses(c.final_poses, c.live), 1);
  EXPECT_NEAR((c.final_poses[5].T_wc.translation() - Eigen::Vector3d(0.05, 0.03, 1)).norm(), 0, 1e-12);
}

TEST(TrajectoryGuard, ABadLivePoseThatBaSetRightIsKept) {
  Case c = straight_run();
  c.live[5].translation().z() += 0.25;  // tracking 25 cm off on a blurred frame;
                                        // the final pose is on the path
  const Eigen::Isometry3d right = c.final_poses[5].T_wc;
  EXPECT_EQ(repair_isolated_poses(c.final_poses, c.live), 0);
  EXPECT_TRUE(c.final_poses[5].T_wc.isApprox(right));
}

TEST(TrajectoryGuard, AShiftTheNextFramesShareIsKept) {
  Case c = straight_run();
  for (std::size_t i = 5; i < 10; ++i) c.final_poses[i].T_wc.translation().x() += 0.5;  // a loop bend from frame 5 on
  const Trajectory before = c.final_poses;
  EXPECT_EQ(repair_isolated_poses(c.final_poses, c.live), 0);
  EXPECT_TRUE(c.final_poses[5].T_wc.isApprox(before[5].T_wc));
}

}  // namespace
}  // namespace varslam::slam
