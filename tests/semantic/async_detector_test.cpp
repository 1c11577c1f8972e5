#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "semantic/async_detector.hpp"

namespace varslam::semantic {
namespace {

// Takes 200 ms per frame and reports one box whose x is the frame's timestamp, so results are traceable.
class SlowFakeDetector final : public Detector {
 public:
  explicit SlowFakeDetector(std::atomic<int>* calls, bool throw_on_odd = false)
      : calls_(calls), throw_on_odd_(throw_on_odd) {}
  Detections detect(const cv::Mat& bgr, double timestamp) override {
    ++*calls_;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    if (throw_on_odd_ && static_cast<int>(timestamp) % 2 == 1) throw std::runtime_error("broken frame");
    Detection d;
    d.timestamp = timestamp;
    d.label = "person";
    d.box = cv::Rect2f(static_cast<float>(timestamp), 0, 10, static_cast<float>(bgr.rows));
    return {d};
  }
  std::string name() const override { return "slow-fake"; }

 private:
  std::atomic<int>* calls_;
  bool throw_on_odd_;
};

TEST(AsyncDetector, SubmitNeverWaitsForTheDetector) {
  std::atomic<int> calls{0};
  AsyncDetector async(std::make_unique<SlowFakeDetector>(&calls));
  EXPECT_FALSE(async.latest().has_value());
  cv::Mat img(48, 64, CV_8UC3, cv::Scalar::all(0));
  const int n = 20;
  for (int i = 0; i < n; ++i) {
    img.setTo(cv::Scalar::all(i));  // the async copy must not see later writes
    async.submit(img, i);
  }
  // Twenty submits done while the detector could at most have started one 200 ms frame: a blocking submit would
  // have run the detector on (nearly) every frame by now.
  EXPECT_LE(calls.load(), 2);
  const auto stale = async.latest();
  EXPECT_TRUE(!stale || stale->timestamp < n - 1) << "boxes are stale while the detector is busy";

  async.wait_idle();
  const auto fresh = async.latest();
  ASSERT_TRUE(fresh.has_value());
  EXPECT_DOUBLE_EQ(fresh->timestamp, n - 1);  // the last submitted frame replaced every pending one
  ASSERT_EQ(fresh->detections.size(), 1u);
  EXPECT_FLOAT_EQ(fresh->detections[0].box.x, static_cast<float>(n - 1));
  EXPECT_GE(fresh->latency_s, 0.19);
  EXPECT_EQ(async.submitted(), n);
  EXPECT_LT(async.processed(), n);
  EXPECT_EQ(async.processed(), calls.load());
  EXPECT_EQ(async.processed() + async.skipped(), n);
  EXPECT_EQ(async.name(), "slow-fake");
}

TEST(AsyncDetector, WaitIdleGivesDeterministicPerFrameResults) {
  std::atomic<int> calls{0};
  AsyncDetector async(std::make_unique<SlowFakeDetector>(&calls));
  const cv::Mat img(8, 8, CV_8UC3, cv::Scalar::all(0));
  for (int i = 0; i < 2; ++i) {
    async.submit(img, 10 + i);
    async.wait_idle();
    ASSERT_TRUE(async.latest().has_value());
    EXPECT_DOUBLE_EQ(async.latest()->timestamp, 10 + i);
  }
  EXPECT_EQ(async.processed(), 2);
  EXPECT_EQ(async.skipped(), 0);
}

TEST(AsyncDetector, AFailingFrameGivesNoBoxesAndTheWorkerCarriesOn) {
  std::atomic<int> calls{0};
  AsyncDetector async(std::make_unique<SlowFakeDetector>(&calls, /*throw_on_odd=*/true));
  const cv::Mat img(8, 8, CV_8UC3, cv::Scalar::all(0));
  async.submit(img, 1);
  async.wait_idle();
  ASSERT_TRUE(async.latest().has_value());
  EXPECT_TRUE(async.latest()->detections.empty());
  async.submit(img, 2);
  async.wait_idle();
  EXPECT_EQ(async.latest()->detections.size(), 1u);
}

TEST(AsyncDetector, DestructionWithWorkPendingDoesNotHang) {
  std::atomic<int> calls{0};
  {
    AsyncDetector async(std::make_unique<SlowFakeDetector>(&calls));
    const cv::Mat img(8, 8, CV_8UC3, cv::Scalar::all(0));
    for (int i = 0; i < 5; ++i) async.submit(img, i);
  }  // joins after at most the frame in progress
  EXPECT_LE(calls.load(), 1);
}

}  // namespace
}  // namespace varslam::semantic
