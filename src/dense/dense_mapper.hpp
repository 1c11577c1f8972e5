#pragma once
// The dense map of the static world: every keyframe's depth, colour and mover mask are kept (downsampled by
// dense.pixel_step) with a way to read the keyframe's current pose, and fused into a TSDF (dense/tsdf_volume.hpp).
//  - deterministic mode: nothing is fused while tracking; finish() (or a mesh asked for earlier) fuses every keyframe
//    from its current pose, in keyframe order: the same input gives the same map.
//  - real-time mode: a worker thread fuses each keyframe as it comes, at the pose it has then; when idle it takes
//    out and fuses again every keyframe whose pose moved (Local BA, a loop) by more than dense.reintegrate_m or
//    dense.reintegrate_deg since it was fused. finish() fuses everything again from the final poses, so the map
//    written at the end agrees with the final trajectory in both modes.
// Owns its keyframe store and volume; add() and finish() from one thread, the readers from any. add() takes only
// the queue's lock, never the volume's: the tracking thread does not wait for a fusion or a reader. Readers get a
// shared copy of the volume as last fused (snapshot()): they wait for neither.
#include <Eigen/Geometry>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "core/camera.hpp"
#include "dense/mover_mask.hpp"
#include "dense/tsdf_volume.hpp"

namespace varslam {
struct Settings;
}

namespace varslam::dense {

struct DenseConfig {
  bool enabled = false;
  TsdfConfig tsdf;
  int pixel_step = 2;           // keep every n-th pixel of the keyframes' images
  bool exclude_movers = true;   // leave out what the system knows moved (false: fuse every pixel)
  float point_radius_px = 12;   // disc left out around a keypoint flagged moving
  int margin_px = 3;            // mover mask dilation
  double reintegrate_m = 0.01, reintegrate_deg = 0.5;
};

/// The `dense` section of the settings (ConfigError naming the key for a bad value).
DenseConfig dense_config(const Settings& settings);

/// The keyframe's current camera-to-world pose (called from the worker thread: must be thread-safe).
using PoseFn = std::function<Eigen::Isometry3d()>;

struct DenseKeyframe {
  long id = 0;
  double timestamp = 0;
  cv::Mat depth;   // CV_32FC1 metres, the camera's size
  cv::Mat bgr;     // CV_8UC3 or empty
  MoverMaskInputs movers;  // what moved in it (ignored unless exclude_movers); the mask is made off the caller's thread
  PoseFn pose;
};

struct DenseStats {
  std::size_t keyframes = 0, integrations = 0, reintegrations = 0, rebuilds = 0;
  std::size_t preview_fusions = 0;  // deterministic mode: fusions for a live view (preview_step()), not counted above
  std::vector<double> integrate_ms;  // per fused keyframe (incremental or final), in order
  double final_rebuild_ms = 0;
  std::size_t blocks = 0;
  double moving_pixel_share = 0;  // of the valid depth pixels, over all keyframes fused last
};

class DenseMapper {
 public:
  DenseMapper(const DenseConfig& cfg, const PinholeCamera& camera, bool threaded);
  ~DenseMapper();
  DenseMapper(const DenseMapper&) = delete;
  DenseMapper& operator=(const DenseMapper&) = delete;

  /// Takes the keyframe (its images are not copied: do not write into them afterwards). Real-time mode: returns at
  /// once, the worker makes its mover mask and fuses it.
  void add(DenseKeyframe kf);
  /// Fuses every keyframe again from its current (final) pose; stops the worker.
  void finish();

  /// The map now (deterministic mode before finish(): fused from the current poses first).
  Mesh mesh();
  std::vector<OccupancyVoxel> occupancy();
  DenseStats stats() const;

  /// Deterministic mode: fuses one keyframe not fused yet, else one whose pose moved, from its current pose, for a
  /// live view; false when there is nothing to do. What finish() writes does not change (it fuses every keyframe
  /// again). Real-time mode: false (the worker does this).
  bool preview_step();
  /// The volume as last fused, to read from any thread without a lock (it never changes; the next fusion makes a
  /// new one). Real-time mode: as of the worker's last keyframe.
  std::shared_ptr<const TsdfVolume> snapshot() const;
  const DenseConfig& config() const { return cfg_; }
  /// The volume, for evaluation: after finish() only.
  const TsdfVolume& volume() const { return volume_; }

 private:
  struct Stored {
    long id = 0;
    double timestamp = 0;
    cv::Mat depth, bgr, movers;  // downsampled
    PoseFn pose;
    bool fused = false;
    Eigen::Isometry3d fused_pose = Eigen::Isometry3d::Identity();
  };
  Stored prepare(DenseKeyframe kf) const;
  DepthView view_of(const Stored& s, const Eigen::Isometry3d& T_wc) const;
  /// false when `cancel` stopped it part way (the volume is then fit only to be fused again from scratch).
  bool fuse_locked(Stored& s, bool preview, const std::atomic<bool>* cancel = nullptr);
  /// Fuses the next keyframe not fused yet, else one whose pose moved; false when there was none (or cancelled).
  bool fuse_one_locked(bool preview, const std::atomic<bool>* cancel = nullptr);
  void rebuild_locked();
  /// Moves the keyframes add() queued into the store (deterministic mode: prepared already).
  void take_arrived_locked();
  /// Makes what was fused so far the snapshot readers get.
  void publish_locked();
  void worker();
  /// Cancels the worker's fusion and joins it (stop_ set first).
  void stop_worker();
  /// Deterministic mode: fuses every keyframe from its current pose if any arrived or moved since.
  void bring_up_to_date();
  bool moved(const Stored& s, const Eigen::Isometry3d& now) const;
  DenseConfig cfg_;
  PinholeCamera camera_;  // scaled to the stored images
  bool threaded_;
  // Lock order: fusion_mutex_, queue_mutex_, published_mutex_. Only the fusing thread (real-time mode: the worker,
  // at idle priority) holds fusion_mutex_ for long; readers take only published_mutex_, for a pointer's copy, so a
  // reader never waits for a fusion (nor for a worker the scheduler keeps off the CPU).
  mutable std::mutex queue_mutex_;  // what add() touches
  std::condition_variable wake_;
  std::deque<DenseKeyframe> pending_;  // real-time mode: taken, not yet prepared
  std::deque<Stored> arrived_;         // deterministic mode: prepared, not yet in the store
  std::size_t keyframes_ = 0;
  bool stop_ = false, finished_ = false;
  std::atomic<bool> cancel_{false};  // finish() or the destructor: the worker drops the fusion it is in
  std::mutex fusion_mutex_;  // the store, the working volume and its statistics
  std::deque<Stored> store_;
  std::size_t next_to_fuse_ = 0;
  TsdfVolume volume_;
  DenseStats stats_;
  std::size_t used_pixels_ = 0, moving_pixels_ = 0;
  bool dirty_ = false;
  struct Published {
    std::shared_ptr<const TsdfVolume> volume;
    DenseStats stats;  // without keyframes (the queue's count)
  };
  mutable std::mutex published_mutex_;
  std::shared_ptr<const Published> published_;
  std::thread thread_;
};

/// Binary PLY (x y z float, red green blue uchar; vertex_indices) written atomically.
void write_mesh_ply(const Mesh& mesh, const std::filesystem::path& file);
/// OctoMap binary tree (.bt, what octomap_server and ROS navigation read): occupied and free voxels at `resolution`.
void write_octomap_bt(const std::vector<OccupancyVoxel>& voxels, double resolution, const std::filesystem::path& file);

}  // namespace varslam::dense
