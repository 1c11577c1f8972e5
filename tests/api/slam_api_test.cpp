// The public API as a library user meets it: settings set in code are used, bad frames and times are InputErrors
// that leave the session going, the map and trajectory views are read from another thread while track() runs
// (also under ThreadSanitizer: scripts/sanitize.sh), maps are saved while running and found again, reset starts
// over, and nothing is written to standard output.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>
#include <varslam/varslam.hpp>

#include "bag/bag_from_folder.hpp"
#include "io/dataset.hpp"
#include "slam/e2e_support.hpp"
#ifdef VARSLAM_HAVE_VIEWER
#include <httplib.h>  // after Eigen: it defines names Eigen's headers use
#endif

namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

struct Sequence {
  varslam::Config config;
  std::vector<varslam::RgbdFrame> frames;
};

const Sequence& sequence() {
  static const Sequence s = [] {
    const fs::path dir = varslam::slam::e2e::pipeline_walking_sequence();
    Sequence seq;
    seq.config = varslam::Config::from_file((dir / "settings.yaml").string());
    seq.config.set("semantic.detector", "none");
    const auto ds = varslam::open_dataset(dir, varslam::settings_for_dataset(dir, std::nullopt));
    for (std::size_t i = 0; i < ds->size(); ++i) seq.frames.push_back(ds->load(i));
    return seq;
  }();
  return s;
}

template <typename Fn>
std::string input_error(Fn fn) {
  try {
    fn();
  } catch (const varslam::InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ApiConfig, KeysAreCheckedWhenSetAndReadBack) {
  varslam::Config c;
  c.set("camera.fx", 600.0).set("tracking.kernel", "huber");
  EXPECT_EQ(c.get("camera.fx"), "600");
  EXPECT_EQ(c.get("tracking.kernel"), "huber");
  EXPECT_TRUE(c.given("camera.fx"));
  EXPECT_FALSE(c.given("mapping.tau"));
  EXPECT_THAT(input_error([&] { c.set("tracking.kernl", "huber"); }), HasSubstr("tracking.kernel"));
  EXPECT_THAT(input_error([&] { c.set("camera.fx", "nan"); }), HasSubstr("camera.fx"));
  EXPECT_THAT(input_error([&] { c.get("camera.focal"); }), HasSubstr("unknown settings key 'camera.focal'"));
  const varslam::Config copy = c;  // a deep copy: changing one leaves the other
  c.set("camera.fx", 500.0);
  EXPECT_EQ(copy.get("camera.fx"), "600");
  EXPECT_GT(varslam::Config::keys().size(), 50u);
  EXPECT_EQ(varslam::Config::from_yaml("camera: {fx: 500, fy: 502, cx: 320, cy: 240}").get("camera.fy"), "502");
}

TEST(ApiSlam, SettingsSetInCodeAreTheOnesUsed) {
  varslam::Config c = sequence().config;
  c.set("camera.width", 320.0);
  varslam::Slam slam(c);
  const auto& f = sequence().frames[0];
  EXPECT_THAT(input_error([&] { slam.track(f.bgr, f.depth, f.timestamp); }), HasSubstr("320"));
}

TEST(ApiSlam, BadTimestampsAndImagesAreInputErrorsAndTheSessionGoesOn) {
  varslam::Slam slam(sequence().config);
  const auto& fr = sequence().frames;
  ASSERT_TRUE(slam.track(fr[0].bgr, fr[0].depth, fr[0].timestamp).pose);
  EXPECT_THAT(input_error([&] { slam.track(fr[1].bgr, fr[1].depth, std::nan("")); }), HasSubstr("not a finite"));
  EXPECT_THAT(input_error([&] { slam.track(fr[1].bgr, fr[1].depth, fr[0].timestamp); }), HasSubstr("not after"));
  EXPECT_THAT(input_error([&] { slam.track(fr[1].bgr, fr[1].depth, fr[0].timestamp - 1); }), HasSubstr("not after"));
  EXPECT_THAT(input_error([&] { slam.track(cv::Mat(10, 10, CV_8UC3), fr[1].depth, fr[1].timestamp); }),
              AllOf(HasSubstr("10"), HasSubstr("640")));
  EXPECT_THAT(input_error([&] {
                slam.track(fr[1].bgr, fr[1].depth, fr[1].timestamp, {{1, 2, -5, 3, 1}});
              }),
              HasSubstr("person box"));
  const varslam::TrackedFrame f = slam.track(fr[1].bgr, fr[1].depth, fr[1].timestamp);
  EXPECT_EQ(f.state, varslam::TrackingState::Tracking);
  EXPECT_EQ(slam.live_trajectory().size(), 2u);
  for (const auto& p : slam.live_trajectory()) EXPECT_TRUE(std::isfinite(p.pose.translation[0]));
}

// A mover mask keeps keypoints off its pixels: the first frame's map (world = that camera's frame) holds no point
// that projects into the masked left half, and a mask over the whole image leaves nothing to track.
TEST(ApiSlam, AMoverMaskKeepsTheMapOffItsPixels) {
  const auto& f = sequence().frames[0];
  const double fx = std::stod(sequence().config.get("camera.fx")), cx = std::stod(sequence().config.get("camera.cx"));
  varslam::FrameExtras left;
  left.mover_mask = cv::Mat::zeros(f.bgr.size(), CV_8UC1);
  left.mover_mask.colRange(0, f.bgr.cols / 2).setTo(255);
  {
    varslam::Slam slam(sequence().config);
    ASSERT_TRUE(slam.track(f.bgr, f.depth, f.timestamp, left).pose);
    const auto map = slam.map_snapshot();
    ASSERT_GT(map->points.size(), 50u);
    for (const auto& p : map->points) EXPECT_GE(fx * p.position[0] / p.position[2] + cx, f.bgr.cols / 2 - 1.0);
  }
  {
    varslam::Slam unmasked(sequence().config);
    ASSERT_TRUE(unmasked.track(f.bgr, f.depth, f.timestamp).pose);
    std::size_t on_left = 0;
    for (const auto& p : unmasked.map_snapshot()->points) on_left += fx * p.position[0] / p.position[2] + cx < 300;
    EXPECT_GT(on_left, 50u);  // so the masked run's empty left half is the mask's doing
  }
  varslam::Slam slam(sequence().config);
  varslam::FrameExtras all;
  all.mover_mask = cv::Mat(f.bgr.size(), CV_8UC1, cv::Scalar(1));
  const varslam::TrackedFrame masked = slam.track(f.bgr, f.depth, f.timestamp, all);
  EXPECT_EQ(masked.keypoints, 0);
  EXPECT_FALSE(masked.pose);
  varslam::FrameExtras wrong;
  wrong.mover_mask = cv::Mat::zeros(10, 10, CV_8UC1);
  EXPECT_THAT(input_error([&] { slam.track(f.bgr, f.depth, f.timestamp + 1, wrong); }), HasSubstr("mover mask"));
  EXPECT_TRUE(slam.track(f.bgr, f.depth, f.timestamp + 1).pose);  // the session goes on
}

// The views other threads may read while track() runs, read as fast as they come (ThreadSanitizer runs this).
TEST(ApiSlam, AConsumerThreadReadsTheMapAndTrajectoryWhileTracking) {
  varslam::Slam slam(sequence().config, varslam::Mode::RealTime);
  std::atomic<bool> done{false};
  std::size_t reads = 0, most_keyframes = 0;
  bool shrank = false;
  std::thread reader([&] {
    while (!done) {
      const auto map = slam.map_snapshot();
      shrank |= map->keyframes.size() + 2 < most_keyframes;  // culling may remove a few, never most
      most_keyframes = std::max(most_keyframes, map->keyframes.size());
      for (const auto& p : map->points) ASSERT_TRUE(std::isfinite(p.position[2]));
      const auto live = slam.live_trajectory();
      if (!live.empty()) {
        ASSERT_TRUE(std::isfinite(live.back().pose.translation[0]));
      }
      (void)slam.summary();
      ++reads;
    }
  });
  for (const auto& f : sequence().frames) slam.track(f.bgr, f.depth, f.timestamp);
  slam.finish();
  done = true;
  reader.join();
  EXPECT_GT(reads, 10u);
  EXPECT_FALSE(shrank);
  EXPECT_GT(most_keyframes, 2u);
  EXPECT_EQ(slam.map_snapshot()->keyframes.size(), slam.summary().keyframes);
}

// The dense map through the API: read from another thread while a real-time session tracks (ThreadSanitizer runs
// this), final after finish(); empty when the settings do not ask for it.
TEST(ApiSlam, TheDenseMapIsASnapshotAnyThreadMayRead) {
  varslam::Config config = sequence().config;
  config.set("dense.enabled", "true");
  varslam::Slam slam(config, varslam::Mode::RealTime);
  std::atomic<bool> done{false};
  std::size_t reads = 0;
  std::thread reader([&] {
    while (!done) {
      const auto d = slam.dense_map_snapshot();
      for (const auto& t : d->triangles)
        for (const auto i : t) ASSERT_LT(static_cast<std::size_t>(i), d->vertices.size());
      ++reads;
      varslam::DenseMapRequest surface;  // as a periodic publisher asks (the ROS node's ~dense_map)
      surface.mesh = surface.occupancy = false;
      surface.surface = true;
      const auto s = slam.dense_map_snapshot(surface);
      ASSERT_EQ(s->surface.size(), s->surface_colours.size());
      ASSERT_TRUE(s->vertices.empty() && s->free.empty());
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  for (const auto& f : sequence().frames) slam.track(f.bgr, f.depth, f.timestamp);
  slam.finish();
  done = true;
  reader.join();
  EXPECT_GT(reads, 2u);
  const auto d = slam.dense_map_snapshot();
  EXPECT_GE(d->keyframes, slam.summary().keyframes);  // culled keyframes stay in the dense map (at their parent's pose)
  EXPECT_GT(d->keyframes, 2u);
  EXPECT_DOUBLE_EQ(d->voxel_size, 0.02);
  EXPECT_GT(d->vertices.size(), 5000u);
  EXPECT_EQ(d->colours.size(), d->vertices.size());
  EXPECT_GT(d->occupied.size(), 1000u);
  EXPECT_GT(d->free.size(), d->occupied.size());
  // The surface alone: at one point per voxel cell it is the mesh's vertices; thinned, fewer.
  varslam::DenseMapRequest request;
  request.mesh = request.occupancy = false;
  request.surface = true;
  request.surface_cell_voxels = 1;
  EXPECT_EQ(slam.dense_map_snapshot(request)->surface.size(), d->vertices.size());
  request.surface_cell_voxels = 2;
  const std::size_t thinned = slam.dense_map_snapshot(request)->surface.size();
  EXPECT_LT(thinned * 2, d->vertices.size());
  EXPECT_GT(thinned * 8, d->vertices.size());
  request.surface_cell_voxels = 3;
  EXPECT_THAT([&] { slam.dense_map_snapshot(request); },
              ::testing::ThrowsMessage<varslam::ConfigError>(HasSubstr("surface_cell_voxels")));

  varslam::Slam without(sequence().config);
  without.track(sequence().frames[0].bgr, sequence().frames[0].depth, sequence().frames[0].timestamp);
  EXPECT_TRUE(without.dense_map_snapshot()->vertices.empty());
}

TEST(ApiSlam, AMapSavedWhileRunningIsFoundAgainAndResetStartsOver) {
  const auto& fr = sequence().frames;
  const fs::path map = fs::temp_directory_path() / ("varslam_api_" + std::to_string(::getpid()) + ".map");
  {
    varslam::Slam slam(sequence().config, varslam::Mode::RealTime);
    for (std::size_t i = 0; i < fr.size(); ++i) {
      slam.track(fr[i].bgr, fr[i].depth, fr[i].timestamp);
      if (i == fr.size() - 10) slam.save_map(map.string());  // while mapping runs
    }
    EXPECT_TRUE(fs::exists(map));
    slam.reset();
    EXPECT_EQ(slam.summary().frames, 0u);
    EXPECT_EQ(slam.map_snapshot()->keyframes.size(), 0u);
    EXPECT_TRUE(slam.track(fr[0].bgr, fr[0].depth, fr[0].timestamp).pose);  // a new map from here
  }
  varslam::Slam again(sequence().config);
  again.load_map(map.string());
  again.set_localization_only(true);
  std::size_t localized = 0;
  for (std::size_t i = 5; i < fr.size(); ++i)
    localized += again.track(fr[i].bgr, fr[i].depth, fr[i].timestamp).pose ? 1 : 0;
  EXPECT_GT(localized, (fr.size() - 5) * 9 / 10);
  EXPECT_EQ(again.summary().keyframes, again.map_snapshot()->keyframes.size());
  fs::remove(map);
}

// With the place database unable to find anything (a score no frame reaches), a loaded map is found only through
// the caller's hint, there and only there.
TEST(ApiSlam, RelocalizeNearFindsThePlaceThatTheHintGives) {
  const auto& fr = sequence().frames;
  const fs::path map = fs::temp_directory_path() / ("varslam_hint_" + std::to_string(::getpid()) + ".map");
  varslam::Pose at30;
  {
    varslam::Slam slam(sequence().config);
    for (std::size_t i = 0; i < fr.size(); ++i) {
      const auto f = slam.track(fr[i].bgr, fr[i].depth, fr[i].timestamp);
      if (i == 30) at30 = f.pose.value();
    }
    slam.finish();
    slam.save_map(map.string());
  }
  varslam::Config blind = sequence().config;
  blind.set("relocalization.loaded_map_min_score", 256.0);
  const auto session = [&](const std::optional<varslam::Pose>& hint) {
    varslam::Slam slam(blind);
    slam.load_map(map.string());
    slam.set_localization_only(true);
    if (hint) slam.relocalize_near(*hint, 0.5);
    return slam.track(fr[30].bgr, fr[30].depth, fr[30].timestamp);
  };
  EXPECT_FALSE(session(std::nullopt).pose);
  const varslam::TrackedFrame found = session(at30);
  ASSERT_TRUE(found.pose);
  EXPECT_TRUE(found.relocalized);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(found.pose->translation[k], at30.translation[k], 0.02);
  varslam::Pose elsewhere = at30;
  elsewhere.translation[0] += 3;
  EXPECT_FALSE(session(elsewhere).pose);
  varslam::Slam slam(blind);
  EXPECT_THAT(input_error([&] { slam.relocalize_near(at30, -1); }), HasSubstr("radius"));
  varslam::Pose bad = at30;
  bad.rotation = {0, 0, 0, 2};
  EXPECT_THAT(input_error([&] { slam.relocalize_near(bad); }), HasSubstr("unit quaternion"));
  fs::remove(map);
}

TEST(ApiSlam, ASessionWritesNothingToStandardOutput) {
  (void)sequence();  // read by the test's own (internal) dataset reader, which logs
  ::testing::internal::CaptureStdout();
  {
    varslam::Slam slam(sequence().config);
    for (std::size_t i = 0; i < 10; ++i)
      slam.track(sequence().frames[i].bgr, sequence().frames[i].depth, sequence().frames[i].timestamp);
    slam.finish();
  }
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "");
}

#ifdef VARSLAM_HAVE_VIEWER
TEST(ApiSlam, TheLiveViewerServesItsPageAndStaysUpAcrossAReset) {
  varslam::Slam slam(sequence().config);
  const std::string url = slam.start_viewer({});
  ASSERT_EQ(url.rfind("http://127.0.0.1:", 0), 0u) << url;
  const int port = std::stoi(url.substr(url.rfind(':') + 1));
  EXPECT_EQ(slam.start_viewer({}), url);  // one viewer per session
  for (std::size_t i = 0; i < 5; ++i)
    slam.track(sequence().frames[i].bgr, sequence().frames[i].depth, sequence().frames[i].timestamp);
  httplib::Client c("127.0.0.1", port);
  auto page = c.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_THAT(page->body, HasSubstr("<html"));
  slam.reset();
  slam.track(sequence().frames[5].bgr, sequence().frames[5].depth, sequence().frames[5].timestamp);
  page = c.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  varslam::ViewerOptions taken;
  taken.port = port;
  varslam::Slam other(sequence().config);
  EXPECT_THAT(input_error([&] { other.start_viewer(taken); }), HasSubstr(std::to_string(port)));
}
#endif

TEST(ApiBag, ABagReadThroughTheLibraryTracksLikeItsFolder) {
  if (!varslam::BagReader::supported()) GTEST_SKIP() << "built without ROS bag support";
  const fs::path dir = varslam::slam::e2e::pipeline_walking_sequence();
  const fs::path out = fs::temp_directory_path() / ("varslam_api_bag_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const varslam::Settings folder = varslam::settings_for_dataset(dir, std::nullopt);
  const auto ds = varslam::open_dataset(dir, folder);
  varslam::bag::write_bag_from_dataset(*ds, folder, out / "seq.bag", {});
  varslam::BagTopics topics;
  topics.gt_frame = "kinect";
  EXPECT_EQ(varslam::BagReader((out / "seq.bag").string()).config().get("camera.fx"),
            sequence().config.get("camera.fx"));  // from CameraInfo
  // With the folder's settings file (CameraInfo has no depth baseline), the same session as on the folder.
  const varslam::BagReader bag((out / "seq.bag").string(), topics, (dir / "settings.yaml").string());
  ASSERT_EQ(bag.size(), sequence().frames.size());
  EXPECT_EQ(bag.groundtruth().size(), bag.size());
  varslam::Config config = bag.config();
  config.set("semantic.detector", "none");
  varslam::Slam from_bag(config), from_folder(sequence().config);
  for (std::size_t i = 0; i < bag.size(); ++i) {
    const varslam::BagFrame f = bag.frame(i);
    const auto& g = sequence().frames[i];
    ASSERT_EQ(f.timestamp, g.timestamp);
    const auto a = from_bag.track(f.bgr, f.depth, f.timestamp), b = from_folder.track(g.bgr, g.depth, g.timestamp);
    ASSERT_EQ(a.pose.has_value(), b.pose.has_value());
    if (a.pose) {
      EXPECT_EQ(a.pose->translation, b.pose->translation) << i;
    }
  }
  EXPECT_THAT(input_error([&] { varslam::BagReader((out / "none.bag").string()); }), HasSubstr("does not exist"));
  fs::remove_all(out);
}

TEST(ApiLog, TheCallersSinkGetsTheLines) {
  std::vector<std::string> lines;
  varslam::set_log_sink([&](varslam::LogLevel, const std::string& l) { lines.push_back(l); }, varslam::LogLevel::Debug);
  {
    varslam::Slam slam(sequence().config);
    for (std::size_t i = 0; i < 10; ++i)
      slam.track(sequence().frames[i].bgr, sequence().frames[i].depth, sequence().frames[i].timestamp);
  }
  varslam::set_log_sink({}, varslam::LogLevel::Warn);
  EXPECT_FALSE(lines.empty());
}

}  // namespace
