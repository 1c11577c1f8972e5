// semantic.detector: auto is the paper's system wherever it can be: YOLO when its model is found, else none.
#include <gtest/gtest.h>

#include <filesystem>

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
  if (!std::filesystem::exists(models / "yolo-fastest-1.1-xl.weights")) GTEST_SKIP() << "no model in " << models;
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

}  // namespace
}  // namespace varslam::semantic
