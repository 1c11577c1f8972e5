#include <gtest/gtest.h>

#include "core/error.hpp"
#include "semantic/detector_settings.hpp"

namespace varslam::semantic {
namespace {

Settings from_yaml(const std::string& text) {
  Settings s;
  s.root = YAML::Load(text);
  s.source = "/data/run/settings.yaml";
  return s;
}

TEST(DetectorSettings, MissingSectionGivesDefaults) {
  const SemanticSettings ss = semantic_settings(from_yaml("fps: 30\n"));
  EXPECT_EQ(ss.detector.source, "none");
  EXPECT_FLOAT_EQ(ss.filter.depth_band_m, 0.5f);
  EXPECT_FLOAT_EQ(ss.filter.silhouette_margin_px, 0.0f);
  EXPECT_FLOAT_EQ(ss.filter.min_exclusive_share, 1.0f);
  EXPECT_TRUE(ss.asynchronous);
}

TEST(DetectorSettings, ReadsAndChecksTheOverlapAndSilhouetteKeys) {
  const SemanticSettings ss =
      semantic_settings(from_yaml("semantic:\n  silhouette_margin_px: 6\n  min_exclusive_share: 0.25\n"));
  EXPECT_FLOAT_EQ(ss.filter.silhouette_margin_px, 6.0f);
  EXPECT_FLOAT_EQ(ss.filter.min_exclusive_share, 0.25f);
  EXPECT_THROW(semantic_settings(from_yaml("semantic:\n  silhouette_margin_px: -1\n")), ConfigError);
  EXPECT_THROW(semantic_settings(from_yaml("semantic:\n  min_exclusive_share: 1.5\n")), ConfigError);
}

// A boxes file costs nothing and is read on every frame; a detector that computes runs on every 2nd frame, its result
// taken one frame later. Explicit values win; a lag beyond the frames between detections is refused by name.
TEST(DetectorSettings, DeterministicScheduleResolvesByDetectorCost) {
  const SemanticSettings boxes = semantic_settings(from_yaml("semantic:\n  detector: boxes\n"));
  EXPECT_EQ(resolved_detect_every(boxes), 1);
  EXPECT_EQ(resolved_detect_lag(boxes), 0);
  const SemanticSettings hog = semantic_settings(from_yaml("semantic:\n  detector: hog\n"));
  EXPECT_EQ(resolved_detect_every(hog), 2);
  EXPECT_EQ(resolved_detect_lag(hog), 1);
  const SemanticSettings given =
      semantic_settings(from_yaml("semantic:\n  detector: hog\n  deterministic_detect_every: 3\n"
                                  "  deterministic_detect_lag: 0\n"));
  EXPECT_EQ(resolved_detect_every(given), 3);
  EXPECT_EQ(resolved_detect_lag(given), 0);
  try {
    semantic_settings(from_yaml("semantic:\n  detector: boxes\n  deterministic_detect_lag: 2\n"));
    FAIL() << "a lag of 2 with a detection on every frame was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("semantic.deterministic_detect_lag"), std::string::npos) << e.what();
  }
}

TEST(DetectorSettings, ReadsTheSemanticSection) {
  const SemanticSettings ss = semantic_settings(from_yaml(R"(
semantic:
  detector: yolo
  model: yolo-fastest-1.1_body
  input_size: 416
  conf_threshold: 0.4
  classes: [person, dog]
  label_aliases: {human: person}
  depth_band_m: 0.3
  box_enlarge: 0.2
  asynchronous: false
)"));
  EXPECT_EQ(ss.detector.source, "yolo");
  EXPECT_EQ(ss.detector.model, "yolo-fastest-1.1_body");
  EXPECT_EQ(ss.detector.input_size, 416);
  EXPECT_FLOAT_EQ(ss.detector.conf_threshold, 0.4f);
  EXPECT_EQ(ss.detector.classes, (std::vector<std::string>{"person", "dog"}));
  EXPECT_EQ(ss.detector.label_aliases.at("human"), "person");
  EXPECT_FLOAT_EQ(ss.filter.depth_band_m, 0.3f);
  EXPECT_FLOAT_EQ(ss.filter.box_enlarge, 0.2f);
  EXPECT_FALSE(ss.asynchronous);
}

TEST(DetectorSettings, WrongTypeOrValueNamesFileAndKey) {
  try {
    semantic_settings(from_yaml("semantic:\n  input_size: big\n"));
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/data/run/settings.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("semantic.input_size"), std::string::npos) << e.what();
  }
  EXPECT_THROW(semantic_settings(from_yaml("semantic:\n  detector: maskrcnn\n")), ConfigError);
  EXPECT_THROW(semantic_settings(from_yaml("semantic:\n  input_size: 300\n")), ConfigError);
}

}  // namespace
}  // namespace varslam::semantic
