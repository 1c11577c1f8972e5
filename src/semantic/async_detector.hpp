#pragma once
// Runs a Detector on its own thread so tracking never waits for it: the tracker submits frames and reads the
// freshest finished result; a frame submitted while the worker is busy replaces the pending one.
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "semantic/detector.hpp"

namespace varslam::semantic {

struct DetectionResult {
  double timestamp = 0.0;  // of the image the detections belong to
  Detections detections;
  double latency_s = 0.0;  // wall time from submit() to the result being available
};

class AsyncDetector {
 public:
  explicit AsyncDetector(std::unique_ptr<Detector> det);
  ~AsyncDetector();  // finishes the frame being processed, drops the pending one
  AsyncDetector(const AsyncDetector&) = delete;
  AsyncDetector& operator=(const AsyncDetector&) = delete;

  /// Non-blocking; the image is copied. If a frame is already pending it is replaced (counted as skipped).
  void submit(const cv::Mat& bgr, double timestamp);
  /// Freshest finished result, if any.
  std::optional<DetectionResult> latest() const;
  /// Blocks until no frame is pending or being processed (deterministic mode: submit + wait_idle + latest).
  void wait_idle();

  long submitted() const;  // frames given to submit()
  long processed() const;  // frames the detector actually ran on
  long skipped() const;    // pending frames replaced before the worker took them
  std::string name() const;

 private:
  struct Pending {
    cv::Mat bgr;
    double timestamp = 0.0;
    double submit_time_s = 0.0;
  };
  void run();

  std::unique_ptr<Detector> det_;
  mutable std::mutex mu_;
  std::condition_variable wake_;  // worker: a frame is pending or stop requested
  std::condition_variable idle_;  // wait_idle(): nothing pending, worker not busy
  std::optional<Pending> pending_;
  std::optional<DetectionResult> latest_;
  bool busy_ = false;
  bool stop_ = false;
  long submitted_ = 0, processed_ = 0, skipped_ = 0;
  std::thread worker_;  // last member: started after everything above is initialised
};

}  // namespace varslam::semantic
