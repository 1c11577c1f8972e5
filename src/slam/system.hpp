#pragma once
// The SLAM system: wires tracking and local mapping, in one of two modes.
//  - deterministic: stages run in order in the caller's thread (same input, same output);
//  - real-time: local mapping (then loop closing) on its own thread, frames decoded ahead by the prefetcher, tracking in the
//    caller's thread, optionally paced at the dataset's frame rate.
#include <memory>
#include <vector>

#include "core/trajectory.hpp"
#include "slam/keyframe_database.hpp"
#include "slam/local_mapping.hpp"
#include "slam/loop_closing.hpp"
#include "slam/map_snapshot.hpp"
#include "slam/tracking.hpp"

namespace varslam::slam {

enum class RunMode { Deterministic, RealTime };

class System {
 public:
  /// `observer` (may be null) receives the mapping and loop records, from the thread that made them.
  System(const SlamConfig& cfg, const PinholeCamera& camera, double close_depth, RunMode mode,
         SystemObserver* observer = nullptr);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  /// Tracks one frame (and, in deterministic mode, runs local mapping on any keyframe it made). An exception
  /// that stopped the mapping thread (real-time mode) is rethrown here.
  TrackOutcome process(const RgbdFrame& frame);
  /// Finishes local mapping (real-time mode) so the map is final; rethrows a mapping thread's exception.
  void finish();

  /// Before the first frame: continue from a saved map (compatibility is the caller's check).
  void adopt_map(const SavedMap& saved);
  /// The map as records, after finish() (real-time mode: mapping must be idle).
  SavedMap snapshot(MapFingerprint fingerprint) const;
  /// The same while running: in real-time mode local mapping is paused (its queue drained, so the map is
  /// consistent) for the copy and started again. Call from the thread that calls process().
  SavedMap snapshot_now(MapFingerprint fingerprint);
  /// Local mapping has nothing to do right now (always true in deterministic mode).
  bool mapping_idle() const { return mode_ != RunMode::RealTime || !mapper_.running() || mapper_.idle(); }
  /// Keyframes waiting for local mapping (real time; always 0 in deterministic mode after process()).
  std::size_t mapping_queue() const { return mapper_.queued(); }
  void set_localization_only(bool on) { tracker_.set_localization_only(on); }
  void set_pose_hint(const Eigen::Isometry3d& T_wc, double radius_m) { tracker_.set_pose_hint(T_wc, radius_m); }

  void set_keypoint_filter(KeypointFilterFn fn) { tracker_.set_keypoint_filter(std::move(fn)); }
  void set_extraction_mask(ExtractionMaskFn fn) { tracker_.set_extraction_mask(std::move(fn)); }

  /// Camera-to-world pose of every processed frame that has one (tracked, or re-anchored to a new segment), each
  /// checked against its neighbours (slam/trajectory_guard.hpp); `repaired` gets how many poses the check replaced.
  Trajectory camera_trajectory(bool include_lost = false, int* repaired = nullptr) const;
  Trajectory keyframe_trajectory() const;
  const Map& map() const { return map_; }
  Map& map() { return map_; }
  const Tracker& tracker() const { return tracker_; }
  std::vector<LoopRecord> loops() const { return loop_.loops(); }
  RunMode mode() const { return mode_; }

 private:
  SlamConfig cfg_;
  RunMode mode_;
  Map map_;
  KeyframeDatabase places_;  // filled by loop closing, read by relocalization
  Tracker tracker_;     // constructed before the mapper and loop closer: they take its ScaleInfo
  LocalMapper mapper_;
  LoopCloser loop_;
};

}  // namespace varslam::slam
