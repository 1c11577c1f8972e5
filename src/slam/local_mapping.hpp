#pragma once
// Local mapping: grows and cleans the map around each new keyframe (observations, new points from
// triangulation, fusion of duplicates, Local BA, culling of weak points and redundant keyframes).
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <list>
#include <mutex>
#include <thread>
#include <vector>

#include "slam/config.hpp"
#include "slam/map.hpp"
#include "slam/system_events.hpp"
#include "slam/tracking.hpp"

namespace varslam::slam {

class LocalMapper final : public KeyframeSink {
 public:
  LocalMapper(const MappingConfig& cfg, Map& map, std::shared_ptr<const ScaleInfo> scale, double close_depth);
  ~LocalMapper() override;

  // KeyframeSink
  bool accepts_keyframes() const override;
  std::size_t queued() const override;
  void insert(const KeyFramePtr& kf) override;
  void interrupt_ba() override { abort_ba_ = true; }

  /// Deterministic mode: process every queued keyframe now, in the caller's thread.
  void process_all();
  /// Real-time mode: process keyframes on an own thread until stop().
  void start();
  /// Finishes the queued keyframes and joins the thread.
  void stop();
  /// Real-time mode: waits until the thread is between keyframes and holds it there (keyframes keep queueing) until
  /// resume(): the map is then consistent for a copy without waiting for the whole queue.
  void pause();
  void resume();
  /// No keyframe being processed and none queued.
  bool idle() const;
  bool running() const { return thread_.joinable(); }

  /// Receives a KeyframeMapped record per processed keyframe, on the mapping thread. Set before start().
  void set_observer(SystemObserver* observer) { observer_ = observer; }
  /// The exception that ended the mapping thread (real-time mode), if any; the thread stops taking keyframes.
  std::exception_ptr failure() const;

  /// Called in the mapping thread after each keyframe is processed (loop closing plugs in here).
  void set_keyframe_done(std::function<void(const KeyFramePtr&)> fn) { keyframe_done_ = std::move(fn); }

 private:
  void run();
  /// Records the error that stopped mapping (deterministic or real-time alike) and drops the queue.
  void fail(std::exception_ptr error);
  void process(const KeyFramePtr& kf);
  void add_observations(const KeyFramePtr& kf);
  void cull_recent_points(const KeyFramePtr& kf);
  void triangulate(const KeyFramePtr& kf);
  void fuse_neighbours(const KeyFramePtr& kf);
  void local_ba(const KeyFramePtr& kf);
  void cull_keyframes(const KeyFramePtr& kf);
  void remove_bad_from_map();

  MappingConfig cfg_;
  Map& map_;
  std::shared_ptr<const ScaleInfo> scale_;
  double close_depth_;

  mutable std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::condition_variable idle_cv_;  // busy_ went false
  bool paused_ = false;              // under queue_mutex_
  std::deque<KeyFramePtr> queue_;
  std::atomic<bool> busy_{false};
  std::atomic<bool> abort_ba_{false};
  std::atomic<bool> stop_requested_{false};
  std::thread thread_;

  std::function<void(const KeyFramePtr&)> keyframe_done_;
  std::list<MapPointPtr> recent_points_;
  KeyframeMapped current_;  // the record of the keyframe being processed (mapping thread only)
  SystemObserver* observer_ = nullptr;
  std::exception_ptr failure_;  // written by the mapping thread under queue_mutex_
  std::atomic<bool> failed_{false};
};

}  // namespace varslam::slam
