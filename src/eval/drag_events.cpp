#include "eval/drag_events.hpp"

#include <algorithm>

#include "core/error.hpp"
#include "eval/rpe.hpp"

namespace varslam {

std::vector<DragEvent> find_drag_events(const Trajectory& gt, const Trajectory& live, const DragOptions& options) {
  RpeOptions ro;
  ro.delta_seconds = options.window_seconds;
  RpeResult rpe;
  try {
    rpe = evaluate_rpe(gt, live, ro);
  } catch (const InputError&) {
    return {};
  }
  std::vector<DragEvent> events;
  bool inside = false;
  for (const RpePair& p : rpe.pairs) {
    if (p.translation_error <= options.threshold_m) {
      inside = false;
      continue;
    }
    // A window overlapping the last event's belongs to it: one pull is one event, even if the error dips.
    if (!inside && !events.empty() && p.est_t0 < events.back().end) inside = true;
    if (!inside) events.push_back({p.est_t0, p.est_t1, 0.0});
    inside = true;
    DragEvent& e = events.back();
    e.end = std::max(e.end, p.est_t1);
    e.peak_m = std::max(e.peak_m, p.translation_error);
  }
  return events;
}

}  // namespace varslam
