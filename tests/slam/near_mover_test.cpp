// The near-mover check on constructed frames: a room wall at 4 m behind a box at 1 m. A static box is kept, a box
// that moved is found and the pose comes from the wall; without two depth clusters there is nothing to decide.
#include "slam/near_mover.hpp"

#include <gtest/gtest.h>

#include <random>

namespace varslam::slam {
namespace {

struct Scene {
  std::vector<Eigen::Vector3d> points_w;
  std::vector<optim::Observation> obs;
  std::vector<bool> near;
};

// The camera at T_cw sees `n_far` wall points (depth 3.5-4.5 m) and `n_near` box points (0.9-1.1 m); the box
// points are observed where they would be after the box moved by `box_motion` (world frame). Noise in pixels.
Scene make_scene(const PinholeCamera& cam, const Eigen::Isometry3d& T_cw, int n_far, int n_near,
                 const Eigen::Vector3d& box_motion, double noise_px, unsigned seed = 3, int n_desk = 0,
                 double far_depth = 4.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> n(0, noise_px);
  Scene s;
  const Eigen::Isometry3d T_wc = T_cw.inverse();
  auto add = [&](double depth_lo, double depth_hi, double half_width, const Eigen::Vector3d& motion, bool near) {
    const double z = depth_lo + (depth_hi - depth_lo) * 0.5 * (u(rng) + 1);
    const Eigen::Vector3d p_c(half_width * z * u(rng), 0.7 * half_width * z * u(rng), z);
    const Eigen::Vector3d p_w = T_wc * p_c;
    const Eigen::Vector3d seen_c = T_cw * (p_w + motion);
    optim::Observation o;
    o.uv = cam.project(seen_c) + Eigen::Vector2d(n(rng), n(rng));
    o.u_right = o.uv.x() - cam.bf / seen_c.z() + 0.1 * n(rng);
    o.disparity_weight = 10;
    s.points_w.push_back(p_w);
    s.obs.push_back(o);
    s.near.push_back(near);
  };
  for (int i = 0; i < n_far; ++i) add(far_depth - 0.5, far_depth + 0.5, 0.55, Eigen::Vector3d::Zero(), false);
  for (int i = 0; i < n_near; ++i) add(0.9, 1.1, 0.3, box_motion, true);
  // A static desk between the box and the wall (not a mover: near[k] stays false).
  for (int i = 0; i < n_desk; ++i) add(1.4, 1.8, 0.5, Eigen::Vector3d::Zero(), false);
  return s;
}

optim::PoseOptimConfig pose_config() {
  optim::PoseOptimConfig pc;
  pc.solver = optim::PoseSolver::Dedicated;
  return pc;
}

Eigen::Isometry3d camera_pose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.1, -0.05, 0.3);
  return T;
}

TEST(NearMover, TwoMeansOnLogDepthSeparatesABoxFromTheWall) {
  double near = 0, far = 0, boundary = 0;
  std::vector<double> depths;
  for (int i = 0; i < 50; ++i) depths.push_back(0.95 + 0.002 * i);
  for (int i = 0; i < 80; ++i) depths.push_back(3.6 + 0.01 * i);
  ASSERT_TRUE(split_by_depth(depths, near, far, boundary));
  EXPECT_NEAR(near, 1.0, 0.06);
  EXPECT_NEAR(far, 4.0, 0.1);
  EXPECT_GT(boundary, 1.1);
  EXPECT_LT(boundary, 3.6);
  EXPECT_FALSE(split_by_depth({2.0, 2.0, 2.0}, near, far, boundary));
  EXPECT_FALSE(split_by_depth({}, near, far, boundary));
}

TEST(NearMover, ABoxThatMovedIsFoundAndTheWallGivesThePose) {
  const PinholeCamera cam;
  const Eigen::Isometry3d T_true = camera_pose();
  // The box moved 6 cm sideways since its points were mapped; it has more matches than the wall.
  const Scene s = make_scene(cam, T_true, 120, 200, Eigen::Vector3d(0.06, 0, 0), 0.5);
  // Tracking followed the box: the joint pose is off by about the box's motion.
  Eigen::Isometry3d dragged = T_true;
  dragged.translation() -= T_true.rotation() * Eigen::Vector3d(0.05, 0, 0);
  const NearMoverVerdict v = check_near_mover(cam, dragged, s.points_w, s.obs, pose_config(), {});
  ASSERT_TRUE(v.split);
  ASSERT_TRUE(v.moving);
  EXPECT_EQ(v.near, 200);
  EXPECT_EQ(v.far, 120);
  EXPECT_LT((v.T_far.translation() - T_true.translation()).norm(), 0.01);
  int near_flagged = 0, far_flagged = 0;
  for (std::size_t k = 0; k < s.near.size(); ++k) (s.near[k] ? near_flagged : far_flagged) += v.mover[k];
  EXPECT_GT(near_flagged, 180);
  EXPECT_EQ(far_flagged, 0);
}

TEST(NearMover, AStaticBoxInFrontOfTheWallIsKept) {
  const PinholeCamera cam;
  const Eigen::Isometry3d T_true = camera_pose();
  const Scene s = make_scene(cam, T_true, 120, 200, Eigen::Vector3d::Zero(), 1.0);
  const NearMoverVerdict v = check_near_mover(cam, T_true, s.points_w, s.obs, pose_config(), {});
  EXPECT_TRUE(v.split);
  EXPECT_FALSE(v.moving);
  EXPECT_TRUE(v.mover.empty());
}

TEST(NearMover, NothingToDecideWithoutTwoClustersOrWithTooFewFarPoints) {
  const PinholeCamera cam;
  const Eigen::Isometry3d T_true = camera_pose();
  // Only the wall.
  const Scene wall = make_scene(cam, T_true, 300, 0, Eigen::Vector3d::Zero(), 0.5);
  EXPECT_FALSE(check_near_mover(cam, T_true, wall.points_w, wall.obs, pose_config(), {}).moving);
  // A moved box hiding all but 10 wall points: too few to speak for the room.
  const Scene hidden = make_scene(cam, T_true, 10, 200, Eigen::Vector3d(0.06, 0, 0), 0.5);
  const NearMoverVerdict v = check_near_mover(cam, T_true, hidden.points_w, hidden.obs, pose_config(), {});
  EXPECT_FALSE(v.split);
  EXPECT_FALSE(v.moving);
}

}  // namespace
}  // namespace varslam::slam
