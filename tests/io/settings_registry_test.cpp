// The settings registry: every key declared once, every wrong key or value a named error, the reference current.
#include "io/settings_registry.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>

#include "core/error.hpp"
#include "io/config_error.hpp"
#include "io/temp_dir.hpp"

namespace varslam {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using varslam::testing::config_error;
using varslam::testing::TempDir;


const std::string kCamera =
    "camera: {fx: 500, fy: 500, cx: 320, cy: 240, width: 640, height: 480, fps: 30, baseline: 0.08}\n"
    "depth: {factor: 5000, th_depth: 40}\n";

std::string load_error(const std::string& body) {
  TempDir dir;
  const auto file = dir.write("s.yaml", kCamera + body);
  return config_error([&] { load_settings(file); });
}

TEST(SettingsRegistry, EveryKeyIsDeclaredOnceWithAKnownSectionAndAValidDefault) {
  std::set<std::string_view> names;
  for (const auto& k : setting_keys::all()) {
    EXPECT_TRUE(names.insert(k.name).second) << "declared twice: " << k.name;
    const auto section = k.name.substr(0, k.name.find('.'));
    EXPECT_NE(std::find(std::begin(setting_keys::kSections), std::end(setting_keys::kSections), section),
              std::end(setting_keys::kSections))
        << k.name;
    EXPECT_FALSE(k.meaning.empty()) << k.name;
    if (!k.has_default) continue;
    // The default, written as a --set value, passes the key's own check.
    Settings s = default_settings();
    std::string value = default_text(k);
    if (value == "\"\"") continue;  // empty paths: nothing to write
    EXPECT_NO_THROW(apply_setting_overrides(s, {std::string(k.name) + "=" + value})) << k.name << "=" << value;
  }
  EXPECT_GT(names.size(), 100u);
}

TEST(SettingsRegistry, UnknownSectionInAFileNamesLineAndNearestSection) {
  EXPECT_THAT(load_error("trackng:\n  kernel: huber\n"),
              AllOf(HasSubstr("s.yaml:3:"), HasSubstr("unknown section 'trackng'"), HasSubstr("did you mean tracking?")));
}

TEST(SettingsRegistry, UnknownKeyInAFileNamesLineAndNearestKey) {
  EXPECT_THAT(load_error("tracking: {kernl: huber}\n"),
              AllOf(HasSubstr("s.yaml:3:"), HasSubstr("tracking.kernl"), HasSubstr("did you mean tracking.kernel?")));
  EXPECT_THAT(load_error("mapping:\n  alpha_mx: 1\n"), HasSubstr("did you mean mapping.alpha_max?"));
  // Far from anything: no guess, a pointer to the list instead.
  EXPECT_THAT(load_error("tracking: {zzzzzzzzzzzzzz: 1}\n"), HasSubstr("varslam settings"));
}

TEST(SettingsRegistry, KeyGivenTwiceIsAnError) {
  EXPECT_THAT(load_error("camera:\n  fx: 400\n"), AllOf(HasSubstr("'camera' appears twice"), HasSubstr("lines 1 and 3")));
  EXPECT_THAT(load_error("tracking: {kernel: huber, kernel: none}\n"), HasSubstr("'tracking.kernel' appears twice"));
}

// Only one spelling of a key is read; the other was ignored without a word.
TEST(SettingsRegistry, TwoSpellingsOfOneKeyAreAnErrorNamingBoth) {
  EXPECT_THAT(load_error("Camera1.fx: 600\n"),
              AllOf(HasSubstr("s.yaml: 'camera.fx' (line 1) and 'Camera1.fx' (line 3) both give camera.fx"),
                    HasSubstr("give it once")));
  EXPECT_THAT(load_error("RGBD.DepthMapFactor: 1000\n"),
              HasSubstr("'depth.factor' (line 2) and 'RGBD.DepthMapFactor' (line 3) both give depth.factor"));
  EXPECT_THAT(load_error("tracking.kernel: huber\ntracking: {kernel: none}\n"), HasSubstr("both give tracking.kernel"));
  TempDir dir;
  const std::string orb = "Camera1.fx: 500\nCamera1.fy: 500\nCamera1.cx: 320\nCamera1.cy: 240\n";
  EXPECT_THAT(config_error([&] { load_settings(dir.write("orb.yaml", orb + "Camera.fx: 600\n")); }),
              HasSubstr("'Camera1.fx' (line 1) and 'Camera.fx' (line 5) both give camera.fx"));
  // One spelling per key reads as before, and an override replaces the file's spelling instead of joining it.
  Settings s = load_settings(dir.write("one.yaml", orb + "RGBD.DepthMapFactor: 1000\n"));
  EXPECT_DOUBLE_EQ(s.depth_factor, 1000.0);
  apply_setting_overrides(s, {"camera.fx=600", "depth.factor=5000"});
  EXPECT_DOUBLE_EQ(s.camera.fx, 600.0);
  EXPECT_DOUBLE_EQ(s.depth_factor, 5000.0);
}

// Names are case-sensitive: "Tracking.Kernel" passed as an ignored ORB-SLAM "Tracking." key.
TEST(SettingsRegistry, ANameInAnotherCaseIsAnErrorGivingTheRightSpelling) {
  EXPECT_THAT(load_error("Tracking.Kernel: huber\n"),
              AllOf(HasSubstr("s.yaml:3:"), HasSubstr("'Tracking.Kernel': names are case-sensitive; write "
                                                      "'tracking.kernel'")));
  EXPECT_THAT(load_error("Tracking: {kernel: huber}\n"), HasSubstr("write 'tracking'"));
  EXPECT_THAT(load_error("tracking: {Kernel: huber}\n"), HasSubstr("write 'tracking.kernel'"));
  EXPECT_THAT(load_error("camera1.FX: 500\n"), HasSubstr("write 'Camera1.fx'"));
  EXPECT_NO_THROW(load_settings(TempDir().write("s.yaml", kCamera + "Tracking.Other: 1\n")));  // ORB-SLAM's own
  Settings s = default_settings();
  EXPECT_THAT(config_error([&] { apply_setting_overrides(s, {"Tracking.Kernel=huber"}); }),
              AllOf(HasSubstr("--set 'Tracking.Kernel=huber'"), HasSubstr("write 'tracking.kernel'")));
}

TEST(SettingsRegistry, NanOutOfRangeAndNegativeCountsAreErrors) {
  EXPECT_THAT(load_error("tracking: {barron_alpha: .nan}\n"),
              AllOf(HasSubstr("tracking.barron_alpha"), HasSubstr("finite")));
  EXPECT_THAT(load_error("semantic: {depth_band_m: .nan}\n"), HasSubstr("key 'semantic.depth_band_m'"));
  EXPECT_THAT(load_error("tracking: {close_keyframe_gap: -5}\n"),
              AllOf(HasSubstr("tracking.close_keyframe_gap"), HasSubstr("[1, 1000000]"), HasSubstr("-5")));
  EXPECT_THAT(load_error("orb: {n_levels: 1000}\n"), AllOf(HasSubstr("orb.n_levels"), HasSubstr("[1, 32]")));
  EXPECT_THAT(load_error("semantic: {detector: yolov9}\n"),
              AllOf(HasSubstr("semantic.detector"), HasSubstr("yolo | boxes | hog | none")));
  TempDir dir;
  const auto file = dir.write("cx.yaml", "camera: {fx: 500, fy: 500, cx: 1e300, cy: 240}\n");
  EXPECT_THAT(config_error([&] { load_settings(file); }), AllOf(HasSubstr("camera.cx"), HasSubstr("1e300")));
}

TEST(SettingsRegistry, CommandLineOverridesAreCheckedAndNamedAsSuch) {
  const auto set_error = [](const std::string& o) {
    Settings s = default_settings();
    return config_error([&] { apply_setting_overrides(s, {o}); });
  };
  EXPECT_THAT(set_error("tracking.kernl=huber"),
              AllOf(HasSubstr("--set 'tracking.kernl=huber'"), HasSubstr("did you mean tracking.kernel?")));
  EXPECT_THAT(set_error("trackng.kernel=huber"),
              AllOf(HasSubstr("--set 'trackng.kernel=huber'"), HasSubstr("unknown section 'trackng'")));
  EXPECT_THAT(set_error("nosuch.key=1"), HasSubstr("unknown section 'nosuch'"));
  EXPECT_THAT(set_error("tracking.barron_alpha=.nan"), AllOf(HasSubstr("--set"), HasSubstr("finite")));
  EXPECT_THAT(set_error("tracking.close_keyframe_gap=-5"), AllOf(HasSubstr("--set"), HasSubstr("-5")));
  EXPECT_THAT(set_error("camera.fx=[1, 2"), AllOf(HasSubstr("--set 'camera.fx=[1, 2'"), HasSubstr("not valid YAML")));
  EXPECT_THAT(set_error("tracking.kernel="), HasSubstr("no value given"));
  EXPECT_THAT(set_error("tracking"), HasSubstr("section.key=value"));
  // A good override takes effect, including camera fields read at load time.
  Settings s = default_settings();
  apply_setting_overrides(s, {"tracking.kernel=huber", "camera.fx=600"});
  EXPECT_EQ(setting<std::string>(s, "tracking.kernel"), "huber");
  EXPECT_DOUBLE_EQ(s.camera.fx, 600.0);
}

TEST(SettingsRegistry, OrbSlamKeysWeDoNotUseAreAcceptedAndOthersAreErrors) {
  TempDir dir;
  const auto file = dir.write("orb.yaml",
                              "%YAML:1.0\nFile.version: \"1.0\"\nCamera.type: \"PinHole\"\nCamera1.fx: 500\n"
                              "Camera1.fy: 500\nCamera1.cx: 320\nCamera1.cy: 240\nCamera.RGB: 1\n"
                              "Viewer.PointSize: 2.0\nSystem.LoadAtlasFromFile: \"x\"\nIMU.NoiseGyro: 1e-3\n"
                              "ORBextractor.nFeatures: 1200\n");
  const Settings s = load_settings(file);
  EXPECT_EQ(s.orb.n_features, 1200);
  const auto bad = dir.write("bad.yaml", "Camera1.fx: 500\nCamera1.fy: 500\nCamera1.cx: 320\nCamera1.cy: 240\n"
                                         "ORBextractor.nFeature: 1200\n");
  EXPECT_THAT(config_error([&] { load_settings(bad); }),
              AllOf(HasSubstr("bad.yaml:5:"), HasSubstr("ORBextractor.nFeature")));
}

TEST(SettingsRegistry, OrbSlamCameraModelsWeCannotHonourAreRefused) {
  TempDir dir;
  const std::string cam = "Camera1.fx: 500\nCamera1.fy: 500\nCamera1.cx: 320\nCamera1.cy: 240\n";
  EXPECT_NO_THROW(load_settings(dir.write("pin.yaml", cam + "Camera.type: \"PinHole\"\nCamera.imageScale: 1\n")));
  EXPECT_THAT(config_error([&] { load_settings(dir.write("kb.yaml", cam + "Camera.type: \"KannalaBrandt8\"\n")); }),
              AllOf(HasSubstr("kb.yaml:5:"), HasSubstr("PinHole")));
  EXPECT_THAT(config_error([&] { load_settings(dir.write("sc.yaml", cam + "Camera.imageScale: 0.5\n")); }),
              HasSubstr("Camera.imageScale 1"));
}

TEST(SettingsRegistry, NearestKeySuggestsTyposOnly) {
  EXPECT_EQ(nearest_key("tracking.kernl"), "tracking.kernel");
  EXPECT_EQ(nearest_key("semantic.detecter"), "semantic.detector");
  EXPECT_EQ(nearest_key("mapng", true), "mapping");
  EXPECT_EQ(nearest_key("completely.unrelated.thing"), "");
}

TEST(SettingsRegistry, ReferenceListsEveryKeyAndDocsAreCurrent) {
  const std::string text = settings_reference_text();
  for (const auto& k : setting_keys::all()) EXPECT_THAT(text, HasSubstr(std::string(k.name))) << k.name;
  std::ifstream in(std::string(VARSLAM_SOURCE_DIR) + "/docs/settings.md");
  ASSERT_TRUE(in) << "docs/settings.md missing";
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), settings_reference_markdown())
      << "docs/settings.md is out of date: build/bin/varslam settings --markdown > docs/settings.md";
}

}  // namespace
}  // namespace varslam
