#include "semantic/async_detector.hpp"

#include <spdlog/spdlog.h>

#include <chrono>

namespace varslam::semantic {
namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

AsyncDetector::AsyncDetector(std::unique_ptr<Detector> det) : det_(std::move(det)), worker_([this] { run(); }) {}

AsyncDetector::~AsyncDetector() {
  {
    std::lock_guard lock(mu_);
    stop_ = true;
    pending_.reset();
  }
  wake_.notify_all();
  worker_.join();
}

void AsyncDetector::submit(const cv::Mat& bgr, double timestamp) {
  Pending p{bgr.clone(), timestamp, now_s()};  // copy outside the lock: the caller may reuse its buffer
  {
    std::lock_guard lock(mu_);
    ++submitted_;
    if (pending_) ++skipped_;
    pending_ = std::move(p);
  }
  wake_.notify_one();
}

std::optional<DetectionResult> AsyncDetector::latest() const {
  std::lock_guard lock(mu_);
  return latest_;
}

void AsyncDetector::wait_idle() {
  std::unique_lock lock(mu_);
  idle_.wait(lock, [this] { return !pending_ && !busy_; });
}

long AsyncDetector::submitted() const {
  std::lock_guard lock(mu_);
  return submitted_;
}
long AsyncDetector::processed() const {
  std::lock_guard lock(mu_);
  return processed_;
}
long AsyncDetector::skipped() const {
  std::lock_guard lock(mu_);
  return skipped_;
}
std::string AsyncDetector::name() const { return det_->name(); }

void AsyncDetector::run() {
  for (;;) {
    Pending job;
    {
      std::unique_lock lock(mu_);
      wake_.wait(lock, [this] { return stop_ || pending_.has_value(); });
      if (stop_) break;
      job = std::move(*pending_);
      pending_.reset();
      busy_ = true;
    }
    DetectionResult result;
    result.timestamp = job.timestamp;
    try {
      result.detections = det_->detect(job.bgr, job.timestamp);
    } catch (const std::exception& e) {
      // A failing frame must not kill the thread (or the process through std::terminate): report, no boxes.
      spdlog::warn("detector {} failed on frame {:.6f}: {}", det_->name(), job.timestamp, e.what());
    }
    result.latency_s = now_s() - job.submit_time_s;
    {
      std::lock_guard lock(mu_);
      // Frames are processed in submission order, so this result is always the freshest.
      latest_ = std::move(result);
      ++processed_;
      busy_ = false;
    }
    idle_.notify_all();
  }
  {
    std::lock_guard lock(mu_);
    busy_ = false;
  }
  idle_.notify_all();
}

}  // namespace varslam::semantic
