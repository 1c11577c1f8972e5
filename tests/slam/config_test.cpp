// Stage settings: kernels and their parameters come from the settings file, bad values are named errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "slam/config.hpp"

namespace varslam::slam {
namespace {

namespace fs = std::filesystem;

fs::path write_settings(const std::string& name, const std::string& body) {
  const fs::path p = fs::temp_directory_path() / name;
  std::ofstream(p) << "camera: {fx: 500, fy: 500, cx: 320, cy: 240, width: 640, height: 480, fps: 30, baseline: 0.08}\n"
                   << "depth: {factor: 5000, th_depth: 40}\n"
                   << body;
  return p;
}

// The message of the ConfigError slam_config_from throws on `s`; a test failure (and "") when it throws none.
std::string config_error_of(const Settings& s) {
  try {
    slam_config_from(settings_from_yaml(s.root, s.source));
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected ConfigError";
  return {};
}

// The paper's kernels, with a redescending shape in tracking (the paper's alpha 1 is a setting away).
TEST(SlamConfig, DefaultsAreBarronKernels) {
  const SlamConfig c = slam_config_from(load_settings(write_settings("cfg_default.yaml", "")));
  EXPECT_EQ(c.tracking.kernel.type, optim::KernelType::BarronFixed);
  EXPECT_DOUBLE_EQ(c.tracking.kernel.barron_alpha, -2.0);
  EXPECT_EQ(c.mapping.kernel.type, optim::KernelType::BarronAdaptive);
  EXPECT_EQ(c.orb.n_features, 1000);
}

TEST(SlamConfig, ReadsKernelChoicesPerStage) {
  const SlamConfig c = slam_config_from(load_settings(write_settings(
      "cfg_kernels.yaml",
      "tracking: {kernel: barron-fixed, barron_alpha: 0.5}\n"
      "mapping: {kernel: barron-adaptive, tau: 20, alpha_fit: component, chi2_gates: false}\n")));
  EXPECT_EQ(c.tracking.kernel.type, optim::KernelType::BarronFixed);
  EXPECT_DOUBLE_EQ(c.tracking.kernel.barron_alpha, 0.5);
  EXPECT_EQ(c.mapping.kernel.type, optim::KernelType::BarronAdaptive);
  EXPECT_DOUBLE_EQ(c.mapping.kernel.tau, 20.0);
  EXPECT_EQ(c.mapping.kernel.fit, robust::AlphaFit::PerComponent);
  EXPECT_FALSE(c.mapping.kernel.chi2_gates);
}

TEST(SlamConfig, UnknownKernelNamesFileAndKey) {
  Settings s = load_settings(write_settings("cfg_bad_kernel.yaml", ""));
  s.root["mapping"]["kernel"] = "tukey";
  const std::string msg = config_error_of(s);
  EXPECT_NE(msg.find("cfg_bad_kernel.yaml"), std::string::npos) << msg;
  EXPECT_NE(msg.find("mapping.kernel"), std::string::npos) << msg;
  EXPECT_NE(msg.find("tukey"), std::string::npos) << msg;
}

TEST(SlamConfig, DisparityWeightIsReadAndChecked) {
  Settings s = load_settings(write_settings("cfg_dw.yaml", ""));
  EXPECT_DOUBLE_EQ(slam_config_from(s).tracking.disparity_weight, 10.0);
  s.root["depth"]["disparity_weight"] = 0.0;  // ORB-SLAM3's residual
  EXPECT_DOUBLE_EQ(slam_config_from(s).tracking.disparity_weight, 0.0);
  s.root["depth"]["disparity_weight"] = -2.0;
  const std::string msg = config_error_of(s);
  EXPECT_NE(msg.find("depth.disparity_weight"), std::string::npos) << msg;
  EXPECT_NE(msg.find("cfg_dw.yaml"), std::string::npos) << msg;
}

TEST(SlamConfig, LoopOwnPoseShareIsReadAndChecked) {
  Settings s = load_settings(write_settings("cfg_own.yaml", ""));
  EXPECT_DOUBLE_EQ(slam_config_from(s).loop.max_own_pose_share, 0.2);
  s.root["loop"]["max_own_pose_share"] = 0.0;  // no check
  EXPECT_DOUBLE_EQ(slam_config_from(s).loop.max_own_pose_share, 0.0);
  s.root["loop"]["max_own_pose_share"] = -0.5;
  const std::string msg = config_error_of(s);
  EXPECT_NE(msg.find("loop.max_own_pose_share"), std::string::npos) << msg;
  EXPECT_NE(msg.find("cfg_own.yaml"), std::string::npos) << msg;
}

TEST(SlamConfig, AlphaMaxIsReadAndChecked) {
  Settings s = load_settings(write_settings("cfg_amax.yaml", ""));
  EXPECT_DOUBLE_EQ(slam_config_from(s).mapping.kernel.alpha_max, 1.0);  // capped at pseudo-Huber by default
  EXPECT_DOUBLE_EQ(slam_config_from(s).tracking.kernel.alpha_max, 2.0);
  s.root["mapping"]["alpha_max"] = 0.5;
  EXPECT_DOUBLE_EQ(slam_config_from(s).mapping.kernel.alpha_max, 0.5);
  s.root["mapping"]["alpha_max"] = 3.0;  // above the grid
  const std::string msg = config_error_of(s);
  EXPECT_NE(msg.find("mapping.alpha_max"), std::string::npos) << msg;
}

TEST(SlamConfig, DepthRegistrationIsAutoOrOff) {
  Settings s = load_settings(write_settings("cfg_reg.yaml", ""));
  EXPECT_TRUE(slam_config_from(s).tracking.estimate_registration);
  s.root["depth"]["registration"] = "off";
  EXPECT_FALSE(slam_config_from(s).tracking.estimate_registration);
  s.root["depth"]["registration"] = "yes";
  const std::string msg = config_error_of(s);
  EXPECT_NE(msg.find("depth.registration"), std::string::npos) << msg;
}

TEST(SlamConfig, DepthCameraFxZeroMeansRegisteredDepth) {  // as the settings files before the registry wrote it
  EXPECT_FALSE(slam_config_from(load_settings(write_settings("cfg_rig0.yaml", "depth.camera_fx: 0\n")))
                   .tracking.depth_rig);
  EXPECT_TRUE(slam_config_from(load_settings(write_settings("cfg_rig.yaml", "")))
                  .tracking.estimate_registration);
}

TEST(SlamConfig, RejectsNonPositiveTau) {
  EXPECT_THROW(slam_config_from(load_settings(write_settings("cfg_tau.yaml", "mapping: {tau: -1}\n"))), ConfigError);
}

// The structs' own defaults are the registry's: a default-constructed config equals one read from no settings.
TEST(SlamConfig, StructDefaultsAreTheRegistrysDefaults) {
  const SlamConfig built;
  const SlamConfig read = slam_config_from(default_settings());
  const auto same_kernel = [](const optim::KernelConfig& a, const optim::KernelConfig& b) {
    return a.type == b.type && a.barron_alpha == b.barron_alpha && a.barron_c == b.barron_c && a.tau == b.tau &&
           a.alpha_max == b.alpha_max && a.fit == b.fit && a.chi2_gates == b.chi2_gates;
  };
  EXPECT_TRUE(same_kernel(built.tracking.kernel, read.tracking.kernel));
  EXPECT_TRUE(same_kernel(built.mapping.kernel, read.mapping.kernel));
  EXPECT_EQ(built.tracking.kernel.type, optim::KernelType::BarronFixed);
  EXPECT_DOUBLE_EQ(built.mapping.kernel.alpha_max, 1.0);
  EXPECT_EQ(built.tracking.close_keyframe_gap, read.tracking.close_keyframe_gap);
  EXPECT_EQ(built.tracking.established_age, read.tracking.established_age);
  EXPECT_EQ(built.tracking.min_inliers_local_map, read.tracking.min_inliers_local_map);
  EXPECT_DOUBLE_EQ(built.tracking.disparity_weight, read.tracking.disparity_weight);
  EXPECT_EQ(built.tracking.estimate_registration, read.tracking.estimate_registration);
  EXPECT_EQ(built.mapping.max_ba_keyframes, read.mapping.max_ba_keyframes);
  EXPECT_DOUBLE_EQ(built.mapping.keyframe_redundancy, read.mapping.keyframe_redundancy);
  EXPECT_EQ(built.loop.min_inliers, read.loop.min_inliers);
  EXPECT_DOUBLE_EQ(built.loop.max_own_pose_share, read.loop.max_own_pose_share);
  EXPECT_EQ(built.relocalization.candidates, read.relocalization.candidates);
  EXPECT_EQ(built.orb.n_features, read.orb.n_features);
  EXPECT_EQ(built.extractor, read.extractor);
}

TEST(SlamConfig, ShippedCameraFilesLoad) {
  const fs::path dir = fs::path(VARSLAM_SOURCE_DIR) / "config";
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".yaml") continue;
    const Settings s = load_settings(e.path());
    EXPECT_GT(s.camera.fx, 100.0) << e.path();
    EXPECT_GT(s.camera.bf, 0.0) << e.path();
    EXPECT_NO_THROW(slam_config_from(s)) << e.path();
    ++n;
  }
  EXPECT_GE(n, 5);
}

}  // namespace
}  // namespace varslam::slam
