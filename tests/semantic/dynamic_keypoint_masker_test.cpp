#include <gtest/gtest.h>

#include <atomic>
#include <map>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <thread>

#include "semantic/dynamic_keypoint_masker.hpp"

namespace varslam::semantic {
namespace {

constexpr int kStep = 30;  // px the person moves per frame
const cv::Size kPerson(90, 200);

int person_x(double t) { return 200 + kStep * static_cast<int>(t); }

// Texture with structure at several scales (like real images), so pyramidal LK can follow a 30 px move.
cv::Mat blobs(cv::Size size, int seed) {
  cv::RNG rng(static_cast<uint64_t>(seed));
  cv::Mat sum(size, CV_32FC1, cv::Scalar(0));
  for (int cell : {40, 12, 4}) {
    cv::Mat coarse(std::max(2, size.height / cell), std::max(2, size.width / cell), CV_32FC1), up;
    rng.fill(coarse, cv::RNG::UNIFORM, 0.f, 85.f);
    cv::resize(coarse, up, size, 0, 0, cv::INTER_CUBIC);
    sum += up;
  }
  cv::Mat out;
  sum.convertTo(out, CV_8UC1);
  return out;
}

// Textured static wall at 4 m with a textured person at 1.5 m moving right by kStep px per frame (t = 0, 1, ...).
RgbdFrame make_frame(double t) {
  static const cv::Mat wall = blobs({640, 480}, 1), body = blobs(kPerson, 2);
  RgbdFrame f;
  f.timestamp = t;
  const cv::Rect at(cv::Point(person_x(t), 120), kPerson);
  f.gray = wall.clone();
  body.copyTo(f.gray(at));
  cv::cvtColor(f.gray, f.bgr, cv::COLOR_GRAY2BGR);
  f.depth = cv::Mat(480, 640, CV_32FC1, cv::Scalar(4.0f));
  f.depth(at).setTo(1.5f);
  return f;
}

// The person's box (a little larger than the person) in the frame at time t.
Detections person_detected_at(double t) {
  Detection d;
  d.timestamp = t;
  d.label = "person";
  d.box = cv::Rect2f(static_cast<float>(person_x(t) - 10), 110, 110, 220);
  return {d};
}

// "Detects" the person where make_frame put it. Frames after the first wait for the gate, so the test controls
// exactly which result is the freshest.
class ScriptedDetector final : public Detector {
 public:
  explicit ScriptedDetector(std::atomic<bool>* gate) : gate_(gate) {}
  Detections detect(const cv::Mat&, double t) override {
    while (t > 0.0 && !gate_->load()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    return person_detected_at(t);
  }
  std::string name() const override { return "scripted"; }

 private:
  std::atomic<bool>* gate_;
};

// Opens on scope exit so the detector thread can always finish: declare it AFTER the masker (destroyed first),
// or the masker's destructor would wait for a frame held at a closed gate.
struct Gate {
  std::atomic<bool> open{false};
  ~Gate() { open = true; }
};

// Deterministic mode with the detector waited for on every frame.
SemanticSettings detect_every_frame() {
  SemanticSettings s;
  s.asynchronous = false;
  s.deterministic_detect_every = 1;
  s.deterministic_detect_lag = 0;
  return s;
}

TEST(DynamicKeypointMasker, SynchronousModeUsesThisFramesBoxes) {
  std::atomic<bool> open{true};
  const SemanticSettings s = detect_every_frame();
  DynamicKeypointMasker masker(std::make_unique<ScriptedDetector>(&open), s);
  const RgbdFrame f = make_frame(2);
  const std::vector<cv::KeyPoint> kps = {{300, 200, 7}, {250, 300, 7}, {20, 20, 7}};  // person, wall, wall
  const MaskResult r = masker.process(f, kps);
  EXPECT_TRUE(r.have_detections);
  EXPECT_DOUBLE_EQ(r.staleness_s, 0.0);
  EXPECT_FALSE(r.propagated);
  EXPECT_EQ(r.keep, (std::vector<bool>{false, true, true}));
}

// Tracking asks for the extraction mask first, then filters: one detection per frame serves both.
TEST(DynamicKeypointMasker, ExtractionMaskAndFilterShareTheFramesBoxes) {
  std::atomic<bool> open{true};
  const SemanticSettings s = detect_every_frame();
  DynamicKeypointMasker masker(std::make_unique<ScriptedDetector>(&open), s);
  const RgbdFrame f = make_frame(2);
  const cv::Mat mask = masker.extraction_mask(f);
  ASSERT_FALSE(mask.empty());
  EXPECT_EQ(mask.at<uchar>(200, 300), 0);    // person
  EXPECT_EQ(mask.at<uchar>(300, 250), 255);  // wall
  EXPECT_EQ(mask.at<uchar>(20, 20), 255);    // wall, outside the box
  const MaskResult r = masker.process(f, {{300, 200, 7}, {250, 300, 7}});
  EXPECT_EQ(r.keep, (std::vector<bool>{false, true}));
  EXPECT_EQ(masker.detector_runs(), 1);
  masker.process(make_frame(3), {});
  EXPECT_EQ(masker.detector_runs(), 2);
}

TEST(DynamicKeypointMasker, StaleBoxesArePropagatedToTheCurrentFrame) {
  const std::vector<cv::KeyPoint> kps = {{316, 200, 7}};  // on the person in frame 1, outside its frame-0 box
  for (const bool propagate : {true, false}) {
    SemanticSettings s;
    s.propagate_boxes = propagate;
    std::optional<DynamicKeypointMasker> holder;
    Gate gate;
    DynamicKeypointMasker& masker = holder.emplace(std::make_unique<ScriptedDetector>(&gate.open), s);
    masker.process(make_frame(0), kps);
    masker.wait_for_detector();
    const MaskResult r = masker.process(make_frame(1), kps);  // frame 1's detection is held at the gate
    ASSERT_TRUE(r.have_detections);
    EXPECT_DOUBLE_EQ(r.staleness_s, 1.0);
    ASSERT_EQ(r.boxes.size(), 1u);
    EXPECT_EQ(r.propagated, propagate);
    if (propagate) {
      EXPECT_NEAR(r.boxes[0].box.x, person_x(1) - 10, 1.0);
      EXPECT_FALSE(r.keep[0]) << "the person moved, the propagated box follows it";
    } else {
      EXPECT_NEAR(r.boxes[0].box.x, person_x(0) - 10, 1e-3);
      EXPECT_TRUE(r.keep[0]);
    }
  }
}

// Takes a fixed time per frame, so the schedule can be shown not to depend on how long detection takes.
class SlowDetector final : public Detector {
 public:
  explicit SlowDetector(int ms) : ms_(ms) {}
  Detections detect(const cv::Mat&, double t) override {
    std::this_thread::sleep_for(std::chrono::milliseconds(ms_));
    ++runs_on_[static_cast<int>(t)];
    return person_detected_at(t);
  }
  std::string name() const override { return "slow"; }
  std::map<int, int> runs_on_;  // frame -> runs; read after the masker waited for the detector
 private:
  int ms_;
};

// Deterministic mode, detector on every 2nd frame, result taken one frame later: which frames are detected and which
// boxes each frame gets follow from the frame count alone, however long the detector takes.
TEST(DynamicKeypointMasker, DeterministicScheduleDependsOnTheFrameCountNotOnTiming) {
  SemanticSettings s;
  s.asynchronous = false;
  s.deterministic_detect_every = 2;
  s.deterministic_detect_lag = 1;
  std::vector<std::vector<double>> staleness_per_run;
  for (const int ms : {0, 40}) {
    auto det = std::make_unique<SlowDetector>(ms);
    SlowDetector* raw = det.get();
    DynamicKeypointMasker masker(std::move(det), s);
    std::vector<double> staleness;
    for (int t = 0; t < 6; ++t) {
      const MaskResult r = masker.process(make_frame(t), {{static_cast<float>(person_x(t) + 40), 200, 7}});
      staleness.push_back(r.have_detections ? r.staleness_s : -1.0);
      if (r.have_detections) {
        EXPECT_FALSE(r.keep[0]) << "frame " << t << ": the box carried over by optical flow covers the person";
        EXPECT_EQ(r.propagated, r.staleness_s > 0.0);
      }
    }
    masker.wait_for_detector();
    EXPECT_EQ(raw->runs_on_, (std::map<int, int>{{0, 1}, {2, 1}, {4, 1}})) << ms << " ms per detection";
    staleness_per_run.push_back(staleness);
  }
  EXPECT_EQ(staleness_per_run[0], (std::vector<double>{-1, 1, 2, 1, 2, 1}));
  EXPECT_EQ(staleness_per_run[1], staleness_per_run[0]);
}

TEST(DynamicKeypointMasker, NothingIsDroppedBeforeTheFirstDetection) {
  std::optional<DynamicKeypointMasker> masker;
  Gate gate;  // closed: the first frame with t > 0 never finishes during the call
  masker.emplace(std::make_unique<ScriptedDetector>(&gate.open), SemanticSettings{});
  const MaskResult r = masker->process(make_frame(3), {{300, 200, 7}});
  EXPECT_FALSE(r.have_detections);
  EXPECT_EQ(r.keep, (std::vector<bool>{true}));
}

}  // namespace
}  // namespace varslam::semantic
