#pragma once
// The dense map as a layer of the live viewer: its own thread (at idle priority, like the dense map's) follows the
// map's surface (dense/surface_tracker.hpp) at a bounded rate while a browser is connected, and posts the regions
// that changed on the board. The tracking thread never waits for it: it reads the map under the dense map's own
// lock, a few blocks at a time, which add() does not take. In deterministic mode (nothing fused while tracking) it
// also fuses the new keyframes for the view, within a time budget per update (the files written at the end do not
// change).
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <set>
#include <thread>

#include "dense/surface_tracker.hpp"
#include "viewer/viewer_board.hpp"
#include "viewer/viewer_messages.hpp"

namespace varslam::dense {
class DenseMapper;
}

namespace varslam::viewer {

struct DenseLayerOptions {
  double rate = 0.5;    // updates per second at most
  int cell_voxels = 2;  // one point per cube of this many voxels (1, 2, 4 or 8)
};

struct DenseLayerStats {
  std::uint64_t updates = 0, regions_sent = 0, bytes_sent = 0;
  std::size_t points = 0, regions = 0;  // in the layer now
  // Reading the changes and encoding them (not the preview fusion): wall time (the thread runs at idle priority, so
  // it includes waiting for a free core) and the thread's CPU time.
  double last_update_ms = 0, max_update_ms = 0;
  double update_cpu_ms = 0, max_update_cpu_ms = 0;
  double preview_ms = 0;                          // deterministic mode: fusing keyframes for the view, in all
  std::size_t last_update_bytes = 0, max_update_bytes = 0;
};

class DenseLayer {
 public:
  DenseLayer(std::shared_ptr<dense::DenseMapper> map, ViewerBoard& board, const DenseLayerOptions& options);
  ~DenseLayer();
  DenseLayer(const DenseLayer&) = delete;
  DenseLayer& operator=(const DenseLayer&) = delete;

  /// Reads what changed and posts it now, on the caller's thread (tests; after the run: the final map).
  void update();
  /// Stops the thread (after the run, before the final update()). Idempotent.
  void stop();
  /// Stops the thread and takes every region it posted off the board (empty messages): the session's map was
  /// replaced (a reset).
  void clear();
  DenseLayerStats stats() const;
  const dense::DenseMapper& map() const { return *map_; }

 private:
  void loop();
  bool stopping() const;
  /// A region's message fields without its points.
  DenseRegionView region_view(dense::SurfaceTracker::RegionKey region) const;
  void update_locked(std::chrono::milliseconds preview_budget);

  std::shared_ptr<dense::DenseMapper> map_;
  ViewerBoard& board_;
  DenseLayerOptions options_;
  std::mutex update_mutex_;  // one update at a time (the thread, or the caller's)
  dense::SurfaceTracker tracker_;
  std::set<dense::SurfaceTracker::RegionKey> posted_;  // regions with points on the board

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  DenseLayerStats stats_;
  std::thread thread_;
};

}  // namespace varslam::viewer
