// semantic.detector: auto is the paper's system wherever it can be: YOLO when its model is found, else none.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "io/settings_registry.hpp"
#include "semantic/detector_settings.hpp"

namespace varslam::semantic {
namespace {

TEST(DetectorAuto, IsTheDefaultAndFallsBackToNoneWithoutTheModel) {
  Settings s = default_settings();
  EXPECT_EQ(setting<std::string>(s, "semantic.detector"), "auto");
  apply_setting_overrides(s, {"semantic.model=no-such-model-anywhere"});
  EXPECT_EQ(semantic_settings(s).detector.source, "none");
}

TEST(DetectorAuto, PicksYoloWhenTheModelIsFound) {
  const std::filesystem::path models = std::filesystem::path(VARSLAM_SHARED_DIR) / "models";
  if (!std::filesystem::exists(models / "yolo-fastest-1.1_body.weights")) GTEST_SKIP() << "no model in " << models;
  Settings s = default_settings();
  apply_setting_overrides(s, {"semantic.model_dir=" + models.string()});
  EXPECT_EQ(semantic_settings(s).detector.source, "yolo");
  apply_setting_overrides(s, {"semantic.detector=none"});  // asked for: no filter even with the model there
  EXPECT_EQ(semantic_settings(s).detector.source, "none");
}

TEST(DetectorAuto, BoxesFileDefaultsToTheDatasetsBoxesTxt) {
  Settings s = default_settings();
  s.dataset_dir = "/data/seq";
  apply_setting_overrides(s, {"semantic.detector=boxes"});
  EXPECT_EQ(semantic_settings(s).detector.boxes_file, std::filesystem::path("/data/seq/boxes.txt"));
}

// A path given relative to the current folder (what `varslam demo` passes) is taken as given when it exists there.
TEST(DetectorAuto, BoxesFileRelativeToTheCurrentFolderIsKept) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "varslam_boxes_cwd_test";
  std::filesystem::create_directories(dir / "seq");
  std::ofstream(dir / "seq" / "boxes.txt") << "# none\n";
  const auto cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  Settings s = default_settings();
  s.dataset_dir = "seq";
  apply_setting_overrides(s, {"semantic.detector=boxes", "semantic.boxes_file=seq/boxes.txt"});
  const std::filesystem::path got = semantic_settings(s).detector.boxes_file;
  std::filesystem::current_path(cwd);
  EXPECT_EQ(got, std::filesystem::path("seq/boxes.txt"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace varslam::semantic
