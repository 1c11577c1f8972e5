#pragma once
// What the SLAM stages report as they work: one record per processed keyframe (with its Local BA), per loop
// search and closed loop. Handed to a SystemObserver from the thread that did the work (the caller's in
// deterministic mode, the mapping thread in real-time mode); the pipeline (pipeline/slam.hpp) queues them and
// hands them to its observers on the caller's thread.
#include <optional>
#include <vector>

namespace varslam::slam {

/// What one Local BA did (for the run's metrics and the alpha-per-keyframe plot).
struct BaRecord {
  long keyframe_id = 0;
  double timestamp = 0;
  int keyframes = 0, fixed_keyframes = 0, points = 0, observations = 0, outliers = 0;
  std::vector<double> alpha_per_iteration;
  double final_alpha = 2.0;   // alpha of the last alternation before the outlier gate
  double fitted_alpha = 2.0;  // the fit behind final_alpha, before mapping.alpha_max capped it
  double refine_alpha = 2.0;  // alpha of the refine solve on the gated inliers
  bool cut_short = false;     // real time: a newer keyframe arrived and the solve stopped before its schedule
  double ms = 0;
};

/// One keyframe through local mapping.
struct KeyframeMapped {
  long keyframe_id = 0;
  double timestamp = 0;
  double ms = 0;                  // the whole processing of the keyframe
  int triangulated_points = 0;    // new points made from it
  int culled_points = 0;          // recent points removed as unreliable
  int culled_keyframes = 0;       // redundant keyframes removed around it
  std::optional<BaRecord> ba;     // empty when Local BA did not run (a newer keyframe waited, or nothing to solve)
  bool ba_skipped = false;        // real time: Local BA did not run because a newer keyframe waited
};

/// One closed loop.
struct LoopRecord {
  long query_keyframe = 0, loop_keyframe = 0;
  double timestamp = 0;
  int score = 0, ransac_inliers = 0, inliers = 0, fused_points = 0;
  double correction_m = 0, correction_deg = 0;  // how far the query keyframe moved
  double pose_graph_ms = 0, global_ba_ms = 0, total_ms = 0;
};

/// One search for a loop (place query and verification) after a keyframe.
struct LoopSearch {
  long keyframe_id = 0;
  double ms = 0;
};

/// Receives the stages' records; called from the thread that produced them.
class SystemObserver {
 public:
  virtual ~SystemObserver() = default;
  virtual void on_keyframe_mapped(const KeyframeMapped&) {}
  virtual void on_loop_search(const LoopSearch&) {}
  virtual void on_loop_closed(const LoopRecord&) {}
};

}  // namespace varslam::slam
