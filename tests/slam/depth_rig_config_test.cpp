// depth.camera_* keys: a separate depth camera (unregistered depth) is described in the settings.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "slam/config.hpp"

namespace varslam::slam {
namespace {

namespace fs = std::filesystem;

Settings settings_with_depth(const std::string& name, const std::string& depth_keys) {
  const fs::path p = fs::temp_directory_path() / name;
  std::ofstream(p) << "camera: {fx: 528, fy: 528, cx: 320, cy: 238, width: 640, height: 480, fps: 30, baseline: 0.08}\n"
                   << "depth: {factor: 1000, th_depth: 40" << depth_keys << "}\n";
  return load_settings(p);
}

TEST(DepthRigConfig, AbsentMeansRegisteredDepth) {
  const SlamConfig c = slam_config_from(settings_with_depth("rig_none.yaml", ""));
  EXPECT_FALSE(c.tracking.depth_rig.has_value());
}

TEST(DepthRigConfig, ReadsIntrinsicsAndOffset) {
  const SlamConfig c = slam_config_from(
      settings_with_depth("rig_full.yaml", ", camera_fx: 585, camera_fy: 586, camera_cx: 321, camera_cy: 241, "
                                           "camera_tx: -0.02, camera_ty: 0.001, camera_tz: 0.002"));
  ASSERT_TRUE(c.tracking.depth_rig.has_value());
  const DepthCameraRig& r = *c.tracking.depth_rig;
  EXPECT_DOUBLE_EQ(r.depth.fx, 585.0);
  EXPECT_DOUBLE_EQ(r.depth.fy, 586.0);
  EXPECT_DOUBLE_EQ(r.depth.cx, 321.0);
  EXPECT_DOUBLE_EQ(r.depth.cy, 241.0);
  EXPECT_DOUBLE_EQ(r.t_colour_depth.x(), -0.02);
  EXPECT_DOUBLE_EQ(r.t_colour_depth.y(), 0.001);
  EXPECT_DOUBLE_EQ(r.t_colour_depth.z(), 0.002);
}

TEST(DepthRigConfig, MissingKeysFallBackToFxAndTheColourCentre) {
  const SlamConfig c = slam_config_from(settings_with_depth("rig_fx.yaml", ", camera_fx: 585"));
  ASSERT_TRUE(c.tracking.depth_rig.has_value());
  const DepthCameraRig& r = *c.tracking.depth_rig;
  EXPECT_DOUBLE_EQ(r.depth.fy, 585.0);
  EXPECT_DOUBLE_EQ(r.depth.cx, 320.0);
  EXPECT_DOUBLE_EQ(r.depth.cy, 238.0);
  EXPECT_TRUE(r.t_colour_depth.isZero());
  EXPECT_FALSE(r.depth.has_distortion());
}

TEST(DepthRigConfig, NegativeFocalIsAConfigError) {
  EXPECT_THROW(slam_config_from(settings_with_depth("rig_bad.yaml", ", camera_fx: -5")), ConfigError);
}

TEST(DepthRigConfig, VoPointsIsASetting) {
  const SlamConfig c = slam_config_from(settings_with_depth("rig_vo.yaml", ""));
  EXPECT_EQ(c.tracking.vo_points, 100);
  Settings s = settings_with_depth("rig_vo2.yaml", "");
  s.root["tracking"]["vo_points"] = 250;
  EXPECT_EQ(slam_config_from(s).tracking.vo_points, 250);
}

}  // namespace
}  // namespace varslam::slam
