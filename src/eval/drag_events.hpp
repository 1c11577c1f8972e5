#pragma once
// "Dragged" events of a live trajectory: moments where the pose a live user got moved more than it should have
// within a short time (a large mover pulling tracking along). Measured without any alignment, from the relative
// pose error over `window_seconds`: an event is a run of pairs whose translation error exceeds `threshold_m`; a
// new event starts only after the error has fallen below the threshold again and the window no longer overlaps
// the last event.
#include <vector>

#include "core/trajectory.hpp"

namespace varslam {

struct DragOptions {
  double window_seconds = 1.0;
  double threshold_m = 0.10;
};

struct DragEvent {
  double start = 0, end = 0;  // estimate timestamps of the first pair's first pose and the last pair's second pose
  double peak_m = 0;          // largest relative translation error in the event
};

/// Empty when fewer than two pairs can be formed (a trajectory shorter than the window).
std::vector<DragEvent> find_drag_events(const Trajectory& gt, const Trajectory& live, const DragOptions& options = {});

}  // namespace varslam
