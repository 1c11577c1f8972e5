#pragma once
// Loop closing: after local mapping has processed a keyframe, look for an older place it sees again, verify it
// geometrically, and correct the drift: rigid correction of the keyframe's neighbourhood, fusion of the
// duplicated points, pose-graph optimisation of every keyframe (SE(3): depth fixes the scale), then a global
// bundle adjustment. Runs in the thread that calls process() (local mapping's), so mapping is paused meanwhile;
// tracking goes on and sees the corrections through the map's update lock.
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "slam/config.hpp"
#include "slam/dense_refinement.hpp"
#include "slam/keyframe_database.hpp"
#include "slam/map.hpp"
#include "slam/system_events.hpp"

namespace varslam::slam {

class LoopCloser {
 public:
  LoopCloser(const LoopConfig& cfg, const optim::KernelConfig& pose_kernel, Map& map, KeyframeDatabase& places,
             std::shared_ptr<const ScaleInfo> scale);

  /// Adds the keyframe to the place database, then looks for and closes a loop; true when one was closed.
  bool process(const KeyFramePtr& kf);

  /// Every loop closed so far.
  std::vector<LoopRecord> loops() const;
  /// Receives a LoopSearch per loop search and a LoopRecord per closed loop, on the thread calling process().
  void set_observer(SystemObserver* observer) { observer_ = observer; }

  /// Bundle adjustment of the whole map (Huber); returns its milliseconds.
  double run_global_ba();
  /// Corrects every keyframe with dense alignments between distant keyframes (slam/dense_refinement.hpp); points
  /// follow their reference keyframes. Call when no other thread changes the map.
  DenseRefinementResult refine_with_depth();

 private:
  struct Detection {
    KeyFramePtr loop_kf;
    int score = 0, ransac_inliers = 0, inliers = 0;
    Eigen::Isometry3d T_cw_corrected;  // the query keyframe's pose in the loop's frame
    std::vector<MapPointPtr> matches;  // per keypoint of the query keyframe: the loop-side point (or null)
    std::vector<MapPointPtr> loop_points;  // the loop keyframe's neighbourhood
  };
  std::optional<Detection> detect(const KeyFramePtr& kf);
  bool verify(const KeyFramePtr& kf, const PlaceCandidate& cand, Detection& out) const;
  /// True when the loop side, matched from the keyframe's own pose, explains a large share (LoopConfig::
  /// max_own_pose_share) of what the loop pose explains and keeps the pose there: no drift, a mover.
  bool loop_side_agrees_with_own_pose(const KeyFramePtr& kf, const std::vector<MapPointPtr>& loop_points,
                                      int loop_inliers, const Eigen::Isometry3d& T_cw_loop) const;
  void correct(const KeyFramePtr& kf, Detection& det, LoopRecord& rec);
  void optimize_pose_graph(const KeyFramePtr& kf, const std::vector<std::pair<KeyFramePtr, KeyFramePtr>>& new_links,
                           const std::map<long, Eigen::Isometry3d>& uncorrected, LoopRecord& rec);
  void global_bundle_adjustment(const KeyFramePtr& kf, LoopRecord& rec);
  /// Moves keyframes and points from `before` to the keyframes' current poses; keyframes and points created
  /// meanwhile (not in `before`) follow `anchor` (which must be in `before`). Call under the map's update lock.
  void propagate(const std::map<long, Eigen::Isometry3d>& before, const KeyFramePtr& anchor);

  LoopConfig cfg_;
  optim::KernelConfig pose_kernel_;
  Map& map_;
  KeyframeDatabase& places_;
  std::shared_ptr<const ScaleInfo> scale_;
  long last_loop_kf_ = -1000000;
  std::vector<std::pair<KeyFramePtr, KeyFramePtr>> loop_links_;  // every loop edge so far (stays in the graph)
  mutable std::mutex records_mutex_;
  std::vector<LoopRecord> records_;
  SystemObserver* observer_ = nullptr;
};

}  // namespace varslam::slam
