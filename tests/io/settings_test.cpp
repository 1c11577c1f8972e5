#include "io/settings.hpp"

#include <fmt/format.h>
#include <gmock/gmock.h>

#include <chrono>
#include <fstream>
#include <gtest/gtest.h>
#include <unistd.h>

#include "core/error.hpp"
#include "io/settings_registry.hpp"
#include "io/config_error.hpp"
#include "io/temp_dir.hpp"

namespace varslam {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using varslam::testing::config_error;
using varslam::testing::TempDir;


const char* kOurs = R"(camera:
  fx: 500.5
  fy: 501.25
  cx: 320
  cy: 240
  width: 640
  height: 480
  fps: 30
  baseline: 0.08
depth: {factor: 5000, th_depth: 40}
orb: {n_features: 1000, scale_factor: 1.2, n_levels: 8, ini_th_fast: 20, min_th_fast: 7}
)";

TEST(Settings, DefaultsAreTumFr1Like) {
  const Settings s = default_settings();
  EXPECT_DOUBLE_EQ(s.camera.fx, 517.3);
  EXPECT_DOUBLE_EQ(s.camera.fy, 516.5);
  EXPECT_DOUBLE_EQ(s.camera.cx, 318.6);
  EXPECT_DOUBLE_EQ(s.camera.cy, 255.3);
  EXPECT_EQ(s.camera.width, 640);
  EXPECT_EQ(s.camera.height, 480);
  EXPECT_DOUBLE_EQ(s.camera.bf, 40.0);
  EXPECT_DOUBLE_EQ(s.depth_factor, 5000.0);
  EXPECT_DOUBLE_EQ(s.th_depth, 40.0);
  EXPECT_DOUBLE_EQ(s.fps, 30.0);
  EXPECT_FALSE(s.camera.has_distortion());
  EXPECT_TRUE(s.source.empty());
  EXPECT_NEAR(s.close_depth_m(), 40.0 * 40.0 / 517.3, 1e-12);
}

TEST(Settings, OurLayoutRoundTripKeepsEveryFieldAndStageSections) {
  TempDir dir;
  Settings s = default_settings();
  s.camera.fx = 612.25;
  s.camera.fy = 611.5;
  s.camera.cx = 330.125;
  s.camera.cy = 241.75;
  s.camera.k1 = 0.1;
  s.camera.k2 = -0.02;
  s.camera.p1 = 0.001;
  s.camera.p2 = -0.002;
  s.camera.k3 = 0.0003;
  s.camera.width = 848;
  s.camera.height = 480;
  s.camera.bf = 612.25 * 0.05;
  s.fps = 15;
  s.depth_factor = 1000;
  s.th_depth = 35.5;
  s.orb = {1500, 1.25, 6, 18, 5};
  s.root = YAML::Load("tracking: {kernel: huber, vo_points: 7, chi2_gates: false}\nmapping: {tau: 12.5}\n");
  const auto file = dir / "settings.yaml";
  save_settings(s, file);

  const Settings r = load_settings(file);
  EXPECT_EQ(r.source, file);
  EXPECT_DOUBLE_EQ(r.camera.fx, s.camera.fx);
  EXPECT_DOUBLE_EQ(r.camera.fy, s.camera.fy);
  EXPECT_DOUBLE_EQ(r.camera.cx, s.camera.cx);
  EXPECT_DOUBLE_EQ(r.camera.cy, s.camera.cy);
  EXPECT_DOUBLE_EQ(r.camera.k1, s.camera.k1);
  EXPECT_DOUBLE_EQ(r.camera.k2, s.camera.k2);
  EXPECT_DOUBLE_EQ(r.camera.p1, s.camera.p1);
  EXPECT_DOUBLE_EQ(r.camera.p2, s.camera.p2);
  EXPECT_DOUBLE_EQ(r.camera.k3, s.camera.k3);
  EXPECT_EQ(r.camera.width, 848);
  EXPECT_EQ(r.camera.height, 480);
  EXPECT_NEAR(r.camera.bf, s.camera.bf, 1e-9);
  EXPECT_DOUBLE_EQ(r.fps, 15);
  EXPECT_DOUBLE_EQ(r.depth_factor, 1000);
  EXPECT_DOUBLE_EQ(r.th_depth, 35.5);
  EXPECT_EQ(r.orb.n_features, 1500);
  EXPECT_DOUBLE_EQ(r.orb.scale_factor, 1.25);
  EXPECT_EQ(r.orb.n_levels, 6);
  EXPECT_EQ(r.orb.ini_th_fast, 18);
  EXPECT_EQ(r.orb.min_th_fast, 5);
  EXPECT_EQ(setting<std::string>(r, "tracking.kernel"), "huber");
  EXPECT_EQ(setting<int>(r, "tracking.vo_points"), 7);
  EXPECT_FALSE(setting<bool>(r, "tracking.chi2_gates"));
  EXPECT_DOUBLE_EQ(setting<double>(r, "mapping.tau"), 12.5);
}

TEST(Settings, WritesBaselineInMetres) {
  TempDir dir;
  Settings s = default_settings();
  s.camera.bf = s.camera.fx * 0.1;
  save_settings(s, dir / "s.yaml");
  const YAML::Node n = YAML::LoadFile((dir / "s.yaml").string());
  EXPECT_NEAR(n["camera"]["baseline"].as<double>(), 0.1, 1e-15);
  EXPECT_DOUBLE_EQ(n["depth"]["factor"].as<double>(), 5000);
  EXPECT_EQ(n["orb"]["n_levels"].as<int>(), 8);
}

TEST(Settings, ReadsThe7ScenesOrbSlam3File) {
  const std::filesystem::path file = std::filesystem::path(VARSLAM_SHARED_DIR) /
                                     "realdata/7scenes_redkitchen/settings.yaml";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "shared data not present: " << file;
  const Settings s = load_settings(file);
  EXPECT_DOUBLE_EQ(s.camera.fx, 585.0);
  EXPECT_DOUBLE_EQ(s.camera.fy, 585.0);
  EXPECT_DOUBLE_EQ(s.camera.cx, 320.0);
  EXPECT_DOUBLE_EQ(s.camera.cy, 240.0);
  EXPECT_EQ(s.camera.width, 640);
  EXPECT_EQ(s.camera.height, 480);
  EXPECT_DOUBLE_EQ(s.fps, 30.0);
  EXPECT_NEAR(s.camera.bf, 585.0 * 0.07732, 1e-9);
  EXPECT_DOUBLE_EQ(s.depth_factor, 1000.0);
  EXPECT_DOUBLE_EQ(s.th_depth, 40.0);
  EXPECT_EQ(s.orb.n_features, 1000);
  EXPECT_DOUBLE_EQ(s.orb.scale_factor, 1.2);
  EXPECT_EQ(s.orb.n_levels, 8);
  EXPECT_EQ(s.orb.ini_th_fast, 20);
  EXPECT_EQ(s.orb.min_th_fast, 7);
  // Flat ORB-SLAM keys (one key with dots in its name) are read under our names.
  EXPECT_DOUBLE_EQ(setting<double>(s, "camera.fx"), 585.0);
  EXPECT_EQ(setting<int>(s, "orb.n_levels"), 8);
}

TEST(Settings, EditedDocumentIsReadAgainIncludingCameraDepthAndOrbFields) {
  const std::filesystem::path file = std::filesystem::path(VARSLAM_SHARED_DIR) /
                                     "realdata/7scenes_redkitchen/settings.yaml";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "shared data not present: " << file;
  Settings r = load_settings(file);
  // `--set` on an ORB-SLAM3 file: each override replaces the file's own spelling of the key.
  apply_setting_overrides(r, {"camera.fx=528", "depth.th_depth=25", "orb.n_features=1500"});
  EXPECT_DOUBLE_EQ(r.camera.fx, 528.0);
  EXPECT_DOUBLE_EQ(r.camera.fy, 585.0);
  EXPECT_DOUBLE_EQ(r.th_depth, 25.0);
  EXPECT_EQ(r.orb.n_features, 1500);
  EXPECT_DOUBLE_EQ(r.depth_factor, 1000.0);
  EXPECT_EQ(r.source, file);
}

TEST(Settings, DefaultsAsADocumentReadBackTheSameAndTakeEdits) {
  // What `--set` does when a dataset has no settings file: the built-in defaults become a document first.
  Settings d = default_settings();
  d.depth_factor = 1000.0;  // e.g. the OpenLORIS default
  YAML::Node doc = YAML::Load(settings_yaml(d));
  const Settings same = settings_from_yaml(doc, {});
  EXPECT_DOUBLE_EQ(same.camera.fx, d.camera.fx);
  EXPECT_DOUBLE_EQ(same.camera.bf, d.camera.bf);
  EXPECT_DOUBLE_EQ(same.depth_factor, 1000.0);
  EXPECT_EQ(same.orb.n_features, d.orb.n_features);
  doc["orb"]["n_features"] = 300;
  EXPECT_EQ(settings_from_yaml(doc, {}).orb.n_features, 300);
}

TEST(Settings, ReadsTheOlderOrbSlamLayoutWithOpenCvHeaderAndMatrixTags) {
  TempDir dir;
  const auto file = dir.write("TUM1.yaml", R"(%YAML:1.0

# older ORB-SLAM layout
Camera.type: "PinHole"
Camera.fx: 517.306408
Camera.fy: 516.469215
Camera.cx: 318.643040
Camera.cy: 255.313989
Camera.k1: 0.262383
Camera.k2: -0.953104
Camera.p1: -0.005358
Camera.p2: 0.002628
Camera.k3: 1.163314
Camera.width: 640
Camera.height: 480
Camera.fps: 30.0
Camera.bf: 40.0
Camera.RGB: 1
ThDepth: 40.0
DepthMapFactor: 5000.0
Tbc: !!opencv-matrix
   rows: 4
   cols: 4
   dt: f
   data: [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]
ORBextractor.nFeatures: 1200
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 20
ORBextractor.minThFAST: 7
Viewer.KeyFrameSize: 0.05
)");
  const Settings s = load_settings(file);
  // Written in our layout it reads again: DepthMapFactor and ThDepth are not kept beside depth.factor/th_depth
  // (found by fuzzing once two spellings of a key became an error).
  save_settings(s, dir / "again.yaml");
  EXPECT_DOUBLE_EQ(load_settings(dir / "again.yaml").depth_factor, 5000.0);
  EXPECT_DOUBLE_EQ(s.camera.fx, 517.306408);
  EXPECT_DOUBLE_EQ(s.camera.cy, 255.313989);
  EXPECT_DOUBLE_EQ(s.camera.k1, 0.262383);
  EXPECT_DOUBLE_EQ(s.camera.k3, 1.163314);
  EXPECT_DOUBLE_EQ(s.camera.bf, 40.0);
  EXPECT_DOUBLE_EQ(s.depth_factor, 5000.0);
  EXPECT_DOUBLE_EQ(s.th_depth, 40.0);
  EXPECT_EQ(s.orb.n_features, 1200);
  EXPECT_EQ(setting<int>(s, "orb.n_features"), 1200);
}

TEST(Settings, WrongTypeNamesFileLineAndKey) {
  TempDir dir;
  std::string text = kOurs;
  text.replace(text.find("fy: 501.25"), 10, "fy: abc");
  const auto file = dir.write("bad.yaml", text);
  const std::string msg = config_error([&] { load_settings(file); });
  EXPECT_THAT(msg, AllOf(HasSubstr(file.string() + ":3:"), HasSubstr("camera.fy"), HasSubstr("'abc'")));
}

TEST(Settings, OrbSlamKeyErrorsUseTheOrbSlamKeyName) {
  TempDir dir;
  const auto file = dir.write("orb.yaml", "%YAML:1.0\nCamera1.fx: 500\nCamera1.fy: -3\nCamera1.cx: 320\n"
                                          "Camera1.cy: 240\nCamera.width: 640\nCamera.height: 480\n");
  const std::string msg = config_error([&] { load_settings(file); });
  EXPECT_THAT(msg, AllOf(HasSubstr(file.string() + ":3:"), HasSubstr("Camera1.fy"), HasSubstr("(0, 100000]")));
}

struct BadValue {
  std::string from, to, key;
};

class SettingsBadValue : public ::testing::TestWithParam<BadValue> {};

TEST_P(SettingsBadValue, IsAConfigErrorNamingFileAndKey) {
  TempDir dir;
  std::string text = kOurs;
  const auto pos = text.find(GetParam().from);
  ASSERT_NE(pos, std::string::npos) << GetParam().from;
  text.replace(pos, GetParam().from.size(), GetParam().to);
  const auto file = dir.write("bad.yaml", text);
  const std::string msg = config_error([&] { load_settings(file); });
  EXPECT_THAT(msg, AllOf(HasSubstr(file.string()), HasSubstr(GetParam().key)));
}

INSTANTIATE_TEST_SUITE_P(
    All, SettingsBadValue,
    ::testing::Values(BadValue{"fx: 500.5", "fx: 0", "camera.fx"}, BadValue{"fy: 501.25", "fy: -1", "camera.fy"},
                      BadValue{"width: 640", "width: 0", "camera.width"},
                      BadValue{"height: 480", "height: 480.5", "camera.height"},
                      BadValue{"fps: 30", "fps: 0", "camera.fps"},
                      BadValue{"baseline: 0.08", "baseline: -0.08", "camera.baseline"},
                      BadValue{"factor: 5000", "factor: 0", "depth.factor"},
                      BadValue{"factor: 5000", "factor: [1, 2]", "depth.factor"},
                      BadValue{"n_levels: 8", "n_levels: 0", "orb.n_levels"},
                      BadValue{"scale_factor: 1.2", "scale_factor: 1.0", "orb.scale_factor"},
                      BadValue{"n_features: 1000", "n_features: many", "orb.n_features"},
                      BadValue{"fx: 500.5", "fx: .nan", "camera.fx"},
                      BadValue{"  fx: 500.5\n", "", "camera.fx"}));  // missing required key

TEST(Settings, MissingFileAndInvalidYamlAreConfigErrors) {
  TempDir dir;
  EXPECT_THAT(config_error([&] { load_settings(dir / "nope.yaml"); }), HasSubstr("nope.yaml"));
  const auto file = dir.write("broken.yaml", "camera:\n  fx: [1, 2\n  fy: 3\n");
  EXPECT_THAT(config_error([&] { load_settings(file); }), AllOf(HasSubstr("broken.yaml:"), HasSubstr("YAML")));
  const auto list = dir.write("list.yaml", "- 1\n- 2\n");
  EXPECT_THAT(config_error([&] { load_settings(list); }), HasSubstr("list.yaml"));
}

TEST(Settings, TypedReadsFallBackToTheRegistryAndRejectWrongTypes) {
  TempDir dir;
  std::string text = kOurs;
  text += "tracking:\n  kernel: huber\n  vo_points: 3.5\n  chi2_gates: maybe\n  tau:\n";
  const auto file = dir.write("s.yaml", text);
  YAML::Node doc = YAML::Load(text);
  // A whole-document check names the first bad key with its line.
  EXPECT_THAT(config_error([&] { load_settings(file); }),
              AllOf(HasSubstr(file.string() + ":14:"), HasSubstr("tracking.vo_points"), HasSubstr("integer")));
  Settings s = default_settings();
  s.root = doc;
  s.source = file;
  EXPECT_EQ(setting<int>(s, "tracking.close_keyframe_gap"), 5);  // absent: the registry's default
  EXPECT_DOUBLE_EQ(setting<double>(s, "tracking.tau"), 10.0);    // null counts as absent
  EXPECT_THAT(config_error([&] { setting<int>(s, "tracking.vo_points"); }),
              AllOf(HasSubstr(file.string()), HasSubstr("tracking.vo_points"), HasSubstr("integer")));
  EXPECT_THAT(config_error([&] { setting<bool>(s, "tracking.chi2_gates"); }),
              AllOf(HasSubstr(file.string()), HasSubstr("tracking.chi2_gates"), HasSubstr("true or false")));
  EXPECT_EQ(setting<std::string>(default_settings(), "tracking.kernel"), "barron-fixed");
  // Reading a key the registry does not declare is a programming error, not a silent default.
  EXPECT_THROW(setting<int>(s, "tracking.nosuch"), std::logic_error);
  EXPECT_THROW(setting<int>(s, "tracking.kernel"), std::logic_error);  // declared as a choice
}

TEST(Settings, AKeyThatIsAMapOrAListIsRefusedByLine) {
  // Found by fuzzing: YAML allows such a key, an ORB-SLAM file read fine, and its copy written back did not read.
  TempDir dir;
  const auto file = dir / "s.yaml";
  std::ofstream(file) << "camera: {fx: 500, fy: 500, cx: 320, cy: 240}\nTbc:\n  rows: 4\n  {}: f\n";
  EXPECT_THAT(config_error([&] { load_settings(file); }),
              AllOf(HasSubstr(file.string() + ":4:"), HasSubstr("a key must be a name, not a map")));
  std::ofstream(file) << "camera: {fx: 500, fy: 500, cx: 320, cy: 240}\n? [a, b]\n: 1\n";
  EXPECT_THAT(config_error([&] { load_settings(file); }), HasSubstr("not a list"));
}

// "Billion laughs": 500 bytes of aliases of aliases are 10^10 values to a walk over the tree. It took minutes
// before; now the read stops at the node budget, before any walk.
TEST(Settings, AnAliasBombIsRefusedWithinASecond) {
  std::string bomb = std::string(kOurs) + "tracking:\n  x0: &x0 [a, a, a, a, a, a, a, a, a, a]\n";
  for (int i = 1; i < 10; ++i) {
    bomb += fmt::format("  x{}: &x{} [", i, i);
    for (int j = 0; j < 10; ++j) bomb += fmt::format("{}*x{}", j ? ", " : "", i - 1);
    bomb += "]\n";
  }
  TempDir dir;
  const auto file = dir.write("bomb.yaml", bomb);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_THAT(config_error([&] { load_settings(file); }),
              AllOf(HasSubstr("bomb.yaml: the YAML expands to more than 10000 values"), HasSubstr("aliases")));
  // An alias inside its own anchor is a cycle (found by fuzzing; the walks that followed overflowed the stack).
  const auto cycle = dir.write("cycle.yaml", std::string(kOurs) + "tracking: &t {kernel: huber, more: [*t]}\n");
  EXPECT_THAT(config_error([&] { load_settings(cycle); }), HasSubstr("an alias inside its own anchor"));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  // Aliases as such are fine.
  const auto fine =
      dir.write("alias.yaml", std::string(kOurs) + "tracking: {kernel: &k huber}\nmapping: {kernel: *k}\n");
  EXPECT_NO_THROW(load_settings(fine));
}

TEST(Settings, ASecondYamlDocumentIsAnErrorNotIgnored) {
  TempDir dir;
  const auto file = dir.write("two.yaml", std::string(kOurs) + "---\ncamera: {fx: 600}\n");
  EXPECT_THAT(config_error([&] { load_settings(file); }),
              AllOf(HasSubstr("two.yaml:13: a second YAML document"), HasSubstr("one document")));
  // A header '---' and a trailing one with nothing after it start no second document.
  EXPECT_NO_THROW(load_settings(dir.write("one.yaml", "%YAML:1.0\n---\n" + std::string(kOurs) + "---\n")));
  // Found by fuzzing: yaml-cpp 0.7 reports empty documents forever after this (YAML::LoadAll never returns).
  const auto forever = dir.write("forever.yaml", ",t" + std::string(57, '\xf3') + "rabking:\n  k_file adaptive\n");
  EXPECT_THAT(config_error([&] { load_settings(forever); }), HasSubstr("forever.yaml: more than 1000 YAML documents"));
}

TEST(Settings, AFileAboveOneMebibyteIsRefused) {
  TempDir dir;
  const auto file = dir.write("big.yaml", std::string(kOurs) + "# " + std::string(1 << 20, 'x') + "\n");
  EXPECT_THAT(config_error([&] { load_settings(file); }), HasSubstr("big.yaml: larger than 1024 KiB"));
}

// A settings file that is there but cannot be read: the error says which and why (it ran with the default camera
// when the dataset's settings.yaml was a link to nowhere).
TEST(Settings, AFileThatCannotBeReadSaysWhy) {
  TempDir dir;
  std::filesystem::create_symlink(dir / "gone.yaml", dir / "link.yaml");
  EXPECT_THAT(config_error([&] { load_settings(dir / "link.yaml"); }),
              AllOf(HasSubstr("link.yaml: the settings file is a symbolic link to"),
                    HasSubstr("gone.yaml, which does not exist")));
  std::filesystem::create_directories(dir / "folder.yaml");
  EXPECT_THAT(config_error([&] { load_settings(dir / "folder.yaml"); }),
              HasSubstr("folder.yaml: is a folder, not a settings file"));
  EXPECT_THAT(config_error([&] { load_settings(dir / "nope.yaml"); }), HasSubstr("nope.yaml: settings file not found"));
}

TEST(Settings, AFileWithoutReadPermissionSaysSo) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads files without permission";
  TempDir dir;
  const auto locked = dir.write("locked.yaml", kOurs);
  std::filesystem::permissions(locked, std::filesystem::perms::none);
  EXPECT_THAT(config_error([&] { load_settings(locked); }),
              HasSubstr("locked.yaml: cannot open the settings file: Permission denied"));
}

}  // namespace
}  // namespace varslam
