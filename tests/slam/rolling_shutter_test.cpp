// Rolling-shutter compensation: keypoints seen by rows exposed one after the other are moved to where the camera
// saw them at the middle row's instant.
#include <gtest/gtest.h>

#include "core/geometry.hpp"
#include "slam/rolling_shutter.hpp"

namespace varslam::slam {
namespace {

constexpr double kReadout = 0.03, kDt = 1.0 / 30;

// The camera motion over one frame interval: a turn of 1 degree about y and x and 1 cm sideways.
Eigen::Isometry3d frame_motion() {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = so3_exp(Eigen::Vector3d(0.3, 1.0, 0.0).normalized() * (M_PI / 180.0));
  m.translation() = Eigen::Vector3d(0.01, 0.0, 0.002);
  return m;
}

// Where a rolling-shutter camera sees `at_middle` (camera coordinates at the middle row's instant): the pixel whose
// row's pose sees the point there, found by fixed-point iteration on the row.
Eigen::Vector3d seen_by_row(const PinholeCamera& cam, const Eigen::Vector3d& at_middle, bool translate) {
  const Eigen::Isometry3d motion = frame_motion();
  const Eigen::Vector3d w = so3_log(motion.rotation());
  double row = cam.project(at_middle).y();
  Eigen::Vector3d at_row = at_middle;
  for (int k = 0; k < 50; ++k) {
    const double share = kReadout * (row / cam.height - 0.5) / kDt;
    const Eigen::Vector3d shift = translate ? Eigen::Vector3d(share * motion.translation()) : Eigen::Vector3d::Zero();
    at_row = so3_exp(share * w) * at_middle + shift;
    row = cam.project(at_row).y();
  }
  return at_row;
}

FrameFeatures features_seeing(const PinholeCamera& cam, const std::vector<Eigen::Vector3d>& at_row,
                              const std::vector<bool>& with_depth) {
  FrameFeatures f;
  f.camera = cam;
  for (std::size_t i = 0; i < at_row.size(); ++i) {
    const Eigen::Vector2d p = cam.project(at_row[i]);
    f.keypoints.emplace_back(cv::Point2f(float(p.x()), float(p.y())), 31.f);
    f.depth.push_back(with_depth[i] ? float(at_row[i].z()) : -1.f);
    f.u_right.push_back(with_depth[i] ? float(p.x() - cam.bf / at_row[i].z()) : -1.f);
  }
  f.build_grid();
  return f;
}

std::vector<float> rows_of(const FrameFeatures& f) {
  std::vector<float> rows;
  for (const cv::KeyPoint& kp : f.keypoints) rows.push_back(kp.pt.y);
  return rows;
}

TEST(RollingShutter, KeypointsWithDepthMoveToWhereTheMiddleRowSawThem) {
  const PinholeCamera cam;
  const std::vector<Eigen::Vector3d> points = {{-0.8, -0.6, 2.0}, {0.5, -0.55, 1.5}, {0.0, 0.0, 3.0}, {0.7, 0.6, 2.5},
                                               {-0.4, 0.5, 1.2}};
  std::vector<Eigen::Vector3d> at_row;
  for (const auto& p : points) at_row.push_back(seen_by_row(cam, p, true));
  FrameFeatures f = features_seeing(cam, at_row, std::vector<bool>(points.size(), true));
  // The rows far from the middle are seen a few pixels away from where the middle row's instant has them.
  EXPECT_GT((cam.project(at_row[0]) - cam.project(points[0])).norm(), 2.0);

  compensate_rolling_shutter(f, rows_of(f), {kReadout, cam.height}, frame_motion(), kDt);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d expected = cam.project(points[i]);
    EXPECT_NEAR(f.keypoints[i].pt.x, expected.x(), 2e-3) << i;
    EXPECT_NEAR(f.keypoints[i].pt.y, expected.y(), 2e-3) << i;
    EXPECT_NEAR(f.depth[i], points[i].z(), 1e-5) << i;
    EXPECT_NEAR(f.u_right[i], expected.x() - cam.bf / points[i].z(), 2e-3) << i;
  }
}

TEST(RollingShutter, KeypointsWithoutDepthTurnWithTheCamera) {
  const PinholeCamera cam;
  // A far point: only the rotation moves it, which is what a keypoint without depth is corrected for.
  const std::vector<Eigen::Vector3d> points = {{-0.8, -0.6, 2.0}, {0.7, 0.6, 2.5}};
  std::vector<Eigen::Vector3d> at_row;
  for (const auto& p : points) at_row.push_back(seen_by_row(cam, p, false));
  FrameFeatures f = features_seeing(cam, at_row, {false, false});
  compensate_rolling_shutter(f, rows_of(f), {kReadout, cam.height}, frame_motion(), kDt);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d expected = cam.project(points[i]);
    EXPECT_NEAR(f.keypoints[i].pt.x, expected.x(), 2e-3) << i;
    EXPECT_NEAR(f.keypoints[i].pt.y, expected.y(), 2e-3) << i;
    EXPECT_LT(f.depth[i], 0.f) << i;
  }
}

TEST(RollingShutter, TheGridFindsKeypointsAtTheirNewPlace) {
  const PinholeCamera cam;
  const Eigen::Vector3d point(-0.8, -0.6, 2.0);
  FrameFeatures f = features_seeing(cam, {seen_by_row(cam, point, true)}, {true});
  compensate_rolling_shutter(f, rows_of(f), {kReadout, cam.height}, frame_motion(), kDt);
  const Eigen::Vector2d p = cam.project(point);
  EXPECT_EQ(f.in_area(p.x(), p.y(), 0.5), std::vector<int>{0});
}

TEST(RollingShutter, AGlobalShutterOrAStillCameraChangesNothing) {
  const PinholeCamera cam;
  const FrameFeatures before = features_seeing(cam, {{-0.8, -0.6, 2.0}, {0.7, 0.6, 2.5}}, {true, false});
  FrameFeatures global = before, still = before;
  compensate_rolling_shutter(global, rows_of(global), {0.0, cam.height}, frame_motion(), kDt);
  compensate_rolling_shutter(still, rows_of(still), {kReadout, cam.height}, Eigen::Isometry3d::Identity(), kDt);
  for (std::size_t i = 0; i < before.size(); ++i) {
    EXPECT_EQ(global.keypoints[i].pt, before.keypoints[i].pt);
    EXPECT_FLOAT_EQ(still.keypoints[i].pt.x, before.keypoints[i].pt.x);
    EXPECT_FLOAT_EQ(still.keypoints[i].pt.y, before.keypoints[i].pt.y);
    EXPECT_FLOAT_EQ(still.depth[i], before.depth[i]);
  }
}

TEST(RollingShutter, OneSensorRowPerKeypointIsRequired) {
  const PinholeCamera cam;
  FrameFeatures f = features_seeing(cam, {{0.0, 0.0, 2.0}}, {true});
  EXPECT_THROW(compensate_rolling_shutter(f, {}, {kReadout, cam.height}, frame_motion(), kDt), std::invalid_argument);
}

}  // namespace
}  // namespace varslam::slam
