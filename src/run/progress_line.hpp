#pragma once
// The observer behind the run's progress line on stderr: frame, speed, map size and tracking state, at most
// once a second (and on the last frame).
#include <chrono>
#include <cstddef>

#include "pipeline/events.hpp"

namespace varslam::run {

class ProgressLine final : public Observer {
 public:
  explicit ProgressLine(std::size_t total_frames);
  ~ProgressLine() override;  // ends the line
  void on_frame(const FrameResult& f) override;

 private:
  using Clock = std::chrono::steady_clock;
  std::size_t total_;
  std::size_t seen_ = 0;
  Clock::time_point start_ = Clock::now(), last_ = Clock::now();
};

}  // namespace varslam::run
