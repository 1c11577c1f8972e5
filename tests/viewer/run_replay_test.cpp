#include "viewer/run_replay.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "slam/e2e_support.hpp"

namespace varslam::viewer {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path replay_sequence() { return slam::e2e::pipeline_walking_sequence(); }

TEST(RunReplay, AFinishedRunShowsItsFramesMapAlphasAndSavedGraph) {
  run::RunOptions ro;
  ro.progress = false;
  const fs::path out = fs::temp_directory_path() / ("varslam_replay_" + std::to_string(::getpid()));
  ro.save_map = out / "walk.map";
  const run::RunSummary s = slam::e2e::run_with(replay_sequence(), out, ro, {"semantic.detector=boxes"});
  const Settings settings = settings_for_dataset(replay_sequence(), std::nullopt);
  const auto dataset = open_dataset(replay_sequence(), settings);

  const FinishedRun plain = load_finished_run(out, dataset.get(), std::nullopt);
  EXPECT_EQ(plain.frames, s.frames);  // every frame of the run on the slider
  EXPECT_GT(plain.map_points, 100u);  // from map.ply
  EXPECT_THAT(plain.greeting, HasSubstr("\"live\":false"));
  EXPECT_THAT(plain.map, HasSubstr("\"final\":true"));
  EXPECT_EQ(plain.log.size(), s.metrics["local_ba"].size() + s.metrics["loops"].size());
  ASSERT_FALSE(plain.log.empty());
  EXPECT_THAT(plain.log.front(), HasSubstr("event: alpha"));

  const FinishedRun with_map = load_finished_run(out, dataset.get(), out / "walk.map");
  EXPECT_EQ(with_map.keyframes, s.keyframes);
  EXPECT_THAT(with_map.map, ::testing::Not(HasSubstr("\"covisibility\":\"\"")));  // the saved graph is drawn

  const auto images = dataset_images(*dataset, 0, plain.frames);
  const auto jpeg = images(3);
  ASSERT_TRUE(jpeg.has_value());
  EXPECT_EQ(static_cast<unsigned char>((*jpeg)[0]), 0xFF);  // JPEG magic
  EXPECT_FALSE(images(plain.frames).has_value());
}

TEST(RunReplay, AFolderThatIsNotARunIsNamed) {
  try {
    (void)load_finished_run("/nonexistent/run", nullptr, std::nullopt);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/run: not a run folder (no CameraTrajectory.txt"));
  }
}

}  // namespace
}  // namespace varslam::viewer
