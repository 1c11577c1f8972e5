// varslam::Pipeline, the pipeline as a library user drives it: images in, poses and events out.
#include "pipeline/slam.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <thread>

#include "core/error.hpp"
#include "io/boxes_io.hpp"
#include "io/dataset.hpp"
#include "io/settings_registry.hpp"
#include "io/trajectory_io.hpp"
#include "slam/e2e_support.hpp"
#include "file_text.hpp"

namespace varslam {
namespace {

namespace fs = std::filesystem;

fs::path walking_sequence() { return slam::e2e::pipeline_walking_sequence(); }

fs::path out_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("varslam_pipeline_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

using test::slurp;

// Counts what arrives, in the caller's thread.
struct Tally final : Observer {
  int frames = 0, keyframe_events = 0, keyframe_results = 0, mapped = 0, local_bas = 0, detections = 0, dropped = 0;
  int registrations = 0;
  bool alphas_recorded = false;
  void on_depth_registration(const DepthRegistrationEvent&) override { ++registrations; }
  void on_frame(const FrameResult& f) override {
    ++frames;
    keyframe_results += f.keyframe;
  }
  void on_keyframe(const KeyframeEvent&) override { ++keyframe_events; }
  void on_keyframe_mapped(const slam::KeyframeMapped& m) override {
    ++mapped;
    if (!m.ba) return;
    ++local_bas;
    alphas_recorded |= !m.ba->alpha_per_iteration.empty();
  }
  void on_detection(const DetectionEvent& d) override {
    ++detections;
    dropped += d.stats.dropped;
  }
};

// The images as a user has them: colour and 16-bit depth PNGs read with OpenCV, timestamps from rgb.txt.
struct Images {
  std::vector<cv::Mat> bgr, depth;
  std::vector<double> stamps;
};

Images read_images(const fs::path& seq, const Settings& settings, std::size_t n) {
  auto ds = open_dataset(seq, settings);
  Images im;
  for (std::size_t i = 0; i < std::min(n, ds->size()); ++i) {
    const RgbdFrame f = ds->load(i);
    im.bgr.push_back(cv::imread(f.rgb_path, cv::IMREAD_COLOR));
    im.depth.push_back(cv::imread(f.depth_path, cv::IMREAD_UNCHANGED));
    im.stamps.push_back(f.timestamp);
  }
  return im;
}

// The dataset's settings with the detector named (its default, auto, depends on whether a model is installed).
Settings settings_without_detector(const fs::path& seq) {
  Settings s = settings_for_dataset(seq, std::nullopt);
  apply_setting_overrides(s, {"semantic.detector=none"});
  return s;
}

TEST(Pipeline, FedImagesGiveTheDatasetRunsTrajectoryAndEveryEvent) {
  const fs::path seq = walking_sequence();
  const Settings settings = settings_without_detector(seq);
  const fs::path out = out_dir("images");
  run::RunOptions ro;
  ro.progress = false;
  ro.max_frames = 40;
  const run::RunSummary ref = run::run_slam(*open_dataset(seq, settings), settings, ro, out);

  const Images im = read_images(seq, settings, 40);
  Pipeline slam(settings);
  Tally tally;
  slam.add_observer(tally);
  std::size_t tracked = 0;
  for (std::size_t i = 0; i < im.bgr.size(); ++i) {
    const FrameResult r = slam.track(im.bgr[i], im.depth[i], im.stamps[i]);
    EXPECT_EQ(r.index, i);
    tracked += r.T_wc.has_value();
  }
  slam.finish();
  EXPECT_EQ(tracked, ref.tracked);
  write_tum_trajectory(slam.camera_trajectory(), out / "api.txt");
  write_tum_trajectory(slam.live_trajectory(), out / "api_live.txt");
  EXPECT_EQ(slurp(out / "api.txt"), slurp(out / "CameraTrajectory.txt"));
  EXPECT_EQ(slurp(out / "api_live.txt"), slurp(out / "LiveTrajectory.txt"));

  EXPECT_EQ(tally.registrations, 1);
  EXPECT_EQ(tally.frames, 40);
  EXPECT_GT(tally.keyframe_events, 1);
  EXPECT_EQ(tally.keyframe_events, tally.keyframe_results);
  EXPECT_EQ(tally.mapped, tally.keyframe_events);  // deterministic: every keyframe mapped before the next frame
  EXPECT_GT(tally.local_bas, 0);
  EXPECT_TRUE(tally.alphas_recorded);
  EXPECT_EQ(tally.detections, 0);
  EXPECT_EQ(slam.summary().detector, "none");
  EXPECT_THROW(slam.track(im.bgr[0], im.depth[0], 99.0), std::logic_error);
}

TEST(Pipeline, CallersBoxesSwitchThePersonFilterOn) {
  const fs::path seq = walking_sequence();
  const Settings settings = settings_without_detector(seq);
  const BoxesByTime boxes = read_boxes_file(seq / "boxes.txt");
  const Images im = read_images(seq, settings, 20);
  Pipeline slam(settings);
  Tally tally;
  slam.add_observer(tally);
  for (std::size_t i = 0; i < im.bgr.size(); ++i)
    slam.track(im.bgr[i], im.depth[i], im.stamps[i], boxes_near(boxes, im.stamps[i]));
  slam.finish();
  EXPECT_EQ(tally.detections, 20);
  EXPECT_GT(tally.dropped, 100) << "the walking people's keypoints are dropped";

  // The same boxes through the settings' boxes file give the same trajectory.
  Settings with_file = settings;
  apply_setting_overrides(with_file, {"semantic.detector=boxes"});  // the dataset's boxes.txt by default
  Pipeline from_file(with_file);
  for (std::size_t i = 0; i < im.bgr.size(); ++i) from_file.track(im.bgr[i], im.depth[i], im.stamps[i]);
  from_file.finish();
  const fs::path out = out_dir("boxes");
  write_tum_trajectory(slam.camera_trajectory(), out / "given.txt");
  write_tum_trajectory(from_file.camera_trajectory(), out / "file.txt");
  EXPECT_EQ(slurp(out / "given.txt"), slurp(out / "file.txt"));
}

TEST(Pipeline, ImagesOfTheWrongSizeOrTypeAreInputErrors) {
  Settings settings = default_settings();
  apply_setting_overrides(settings, {"semantic.detector=none"});
  Pipeline slam(settings);
  const cv::Mat bgr(480, 640, CV_8UC3, cv::Scalar::all(100)), depth(480, 640, CV_16UC1, cv::Scalar::all(5000));
  EXPECT_THROW(slam.track(cv::Mat(240, 320, CV_8UC3), depth, 0.0), InputError);
  EXPECT_THROW(slam.track(bgr, cv::Mat(480, 640, CV_8UC2), 0.0), InputError);
  EXPECT_THROW(slam.track(bgr, cv::Mat(), 0.0), InputError);
  EXPECT_THROW(slam.track(cv::Mat(480, 640, CV_32FC3), depth, 0.0), InputError);
  // Metres as floats are accepted as they are.
  EXPECT_NO_THROW(slam.track(bgr, cv::Mat(480, 640, CV_32FC1, cv::Scalar::all(1.0)), 0.0));
  EXPECT_EQ(slam.summary().frames, 1u);
}

TEST(Pipeline, SettingsBuiltInCodeAreCheckedAndMisuseIsNamed) {
  Settings typo = default_settings();
  typo.root = YAML::Load("tracking: {kernl: huber}");
  EXPECT_THROW(Pipeline{typo}, ConfigError);

  Settings s = default_settings();
  apply_setting_overrides(s, {"semantic.detector=none"});
  Pipeline slam(s);
  EXPECT_THROW(slam.frame_preparation(), std::logic_error);  // depth registration is not decided yet
  slam.calibrate_depth({});
  EXPECT_NO_THROW(slam.frame_preparation());
  RgbdFrame bad;
  bad.gray = cv::Mat(480, 640, CV_8UC1, cv::Scalar(0));
  bad.depth = cv::Mat(480, 640, CV_16UC1, cv::Scalar(0));  // raw depth where metres are due
  EXPECT_THROW(slam.track(bad), InputError);
}

// Real-time mode: mapping and the detector on their own threads, every event still on the caller's thread.
TEST(Pipeline, RealTimeEventsArriveOnTheCallersThread) {
  const fs::path seq = walking_sequence();
  Settings settings = settings_for_dataset(seq, std::nullopt);
  apply_setting_overrides(settings, {"semantic.detector=boxes", "semantic.asynchronous=true"});
  struct ThreadCheck final : Observer {
    std::thread::id caller = std::this_thread::get_id();
    int elsewhere = 0, frames = 0, mapped = 0, detections = 0;
    void note() { elsewhere += std::this_thread::get_id() != caller; }
    void on_frame(const FrameResult&) override { note(), ++frames; }
    void on_detection(const DetectionEvent&) override { note(), ++detections; }
    void on_keyframe_mapped(const slam::KeyframeMapped&) override { note(), ++mapped; }
    void on_loop_search(const slam::LoopSearch&) override { note(); }
  } check;
  const Images im = read_images(seq, settings, 60);
  Pipeline slam(settings, PipelineOptions{RunMode::RealTime, nullptr});
  slam.add_observer(check);
  std::size_t tracked = 0;
  for (std::size_t i = 0; i < im.bgr.size(); ++i) tracked += slam.track(im.bgr[i], im.depth[i], im.stamps[i]).T_wc.has_value();
  slam.finish();
  EXPECT_EQ(check.elsewhere, 0);
  EXPECT_EQ(check.frames, 60);
  EXPECT_EQ(check.detections, 60);
  EXPECT_GT(check.mapped, 1);
  EXPECT_GE(tracked, 55u);
  EXPECT_GE(static_cast<std::size_t>(check.mapped), slam.summary().keyframes) << "every keyframe mapped by finish()";
}

// An observer may leave from inside its own callback.
TEST(Pipeline, ObserverCanRemoveItselfDuringACallback) {
  struct OneShot final : Observer {
    Pipeline* slam = nullptr;
    int calls = 0;
    void on_frame(const FrameResult&) override {
      ++calls;
      slam->remove_observer(*this);
    }
  };
  Settings s = default_settings();
  apply_setting_overrides(s, {"semantic.detector=none"});
  Pipeline slam(s);
  OneShot once;
  once.slam = &slam;
  Tally tally;
  slam.add_observer(once);
  slam.add_observer(tally);
  const cv::Mat bgr(480, 640, CV_8UC3, cv::Scalar::all(100)), depth(480, 640, CV_16UC1, cv::Scalar::all(5000));
  slam.track(bgr, depth, 0.0);
  slam.track(bgr, depth, 0.1);
  EXPECT_EQ(once.calls, 1);
  EXPECT_EQ(tally.frames, 2);
}

}  // namespace
}  // namespace varslam
