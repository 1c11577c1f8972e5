#include "run/progress_line.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>

namespace varslam::run {
namespace {

const char* state_name(TrackState s) {
  switch (s) {
    case TrackState::NotInitialized: return "not_initialized";
    case TrackState::Ok: return "ok";
    case TrackState::Lost: return "lost";
  }
  return "?";
}

}  // namespace

ProgressLine::ProgressLine(std::size_t total_frames) : total_(total_frames) {}

ProgressLine::~ProgressLine() {
  if (seen_ > 0) fmt::print(stderr, "\n");
}

void ProgressLine::on_frame(const FrameResult& f) {
  ++seen_;
  const auto now = Clock::now();
  if (std::chrono::duration<double>(now - last_).count() <= 1.0 && seen_ != total_) return;
  last_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  fmt::print(stderr, "\r[run] frame {}/{}  {:.1f} fps  keyframes {}  points {}  state {}   ", seen_, total_,
             static_cast<double>(seen_) / std::max(elapsed, 1e-9), f.map_keyframes, f.map_points, state_name(f.state));
}

}  // namespace varslam::run
