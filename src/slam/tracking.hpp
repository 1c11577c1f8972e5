#pragma once
// Tracking: estimates the pose of every frame against the map (motion model, reference keyframe, local map)
// and decides when a frame becomes a keyframe. Owns the current and last frame; reads the map.
#include <functional>
#include <memory>
#include <optional>
#include <unordered_set>
#include <vector>

#include "core/rgbd_frame.hpp"
#include "features/feature_extractor.hpp"
#include "slam/config.hpp"
#include "slam/frame.hpp"
#include "slam/keyframe.hpp"
#include "slam/keyframe_database.hpp"
#include "slam/keyframe_localization.hpp"
#include "slam/lost_frame_chain.hpp"
#include "slam/map.hpp"

namespace varslam::slam {

struct FramePoseProblem;

enum class TrackState { NotInitialized, Ok, Lost };

/// Where tracking hands its keyframes (local mapping, directly or through a queue).
class KeyframeSink {
 public:
  virtual ~KeyframeSink() = default;
  virtual bool accepts_keyframes() const = 0;  // idle, ready for the next one
  virtual std::size_t queued() const = 0;
  virtual void insert(const KeyFramePtr& kf) = 0;
  virtual void interrupt_ba() = 0;
};

/// Decides which keypoints tracking may use (the semantic filter plugs in here). keep[i] per keypoint.
using KeypointFilterFn = std::function<std::vector<bool>(const RgbdFrame&, const std::vector<cv::KeyPoint>&)>;
/// Where the extractor may place keypoints on a frame (CV_8UC1, non-zero = allowed; empty = everywhere).
using ExtractionMaskFn = std::function<cv::Mat(const RgbdFrame&)>;

struct FrameTimings {
  double extract_ms = 0, filter_ms = 0, match_ms = 0, pose_ms = 0, track_ms = 0;
};

/// A frame located by global relocalization against a place candidate.
struct Relocalization {
  long keyframe_id = 0;  // the candidate it was located against
  int inliers = 0;
  int place_score = 0;   // signature matches (of 256)
};

/// Residuals of a tracked frame's inlier map-point matches at its final pose (after the last pose optimisation):
/// what the sensor's noise leaves once the pose is solved, a scene-independent statistic (metrics.json "sensor").
struct PoseResiduals {
  std::vector<float> reprojection_px;   // |projected - keypoint| in level-0 pixels, one per inlier
  std::vector<float> depth_m;           // |predicted z - measured z| of the inliers whose keypoint has depth
  std::vector<float> measured_depth_m;  // the measured z of each depth_m entry (to normalise by z^2)
};

/// What tracking made of one keypoint of the frame.
enum class KeypointFate : std::uint8_t { Unmatched = 0, Inlier = 1, Outlier = 2 };

struct TrackOutcome {
  TrackState state = TrackState::NotInitialized;
  bool keyframe = false;
  long keyframe_id = -1;     // the keyframe this frame became (keyframe == true)
  bool new_segment = false;  // tracking was lost and a new map segment started at the predicted pose
  int inliers = 0;
  int keypoints = 0;
  int keypoints_with_depth = 0;
  int depth_edge_rejected = 0;
  FrameTimings timings;
  // The pose tracking gave the frame, camera-to-world, as a live user gets it (later BA and loop corrections move
  // the frame's pose in the final trajectory, not this); empty when the frame was not tracked.
  std::optional<Eigen::Isometry3d> live_T_wc;
  std::optional<Relocalization> relocalized;  // set on the frame global relocalization found
  // The frame's keypoints (undistorted, after the person filter) and, per keypoint, what pose optimisation made of
  // it: an outlier is a match the kernel gave a weight below its gate (chi-square test of the weighted residual).
  std::shared_ptr<const FrameFeatures> features;
  std::vector<KeypointFate> keypoint_fate;
  PoseResiduals residuals;  // empty unless the frame was tracked by pose optimisation
  // The keyframe this frame became (keyframe == true), for consumers that follow its pose (the dense map).
  std::shared_ptr<KeyFrame> new_keyframe;
  // Per keypoint of `features`: on the near mover being followed (no point is built on it).
  std::vector<bool> on_mover;
  // The near mover followed at this frame (slam/mover_track.hpp): its image region and depth band.
  struct MoverRegion {
    Eigen::AlignedBox2f region;
    float near_depth = 0, far_depth = 0, depth_margin = 0;
  };
  std::optional<MoverRegion> mover;
};

/// Pose of a frame kept relative to its reference keyframe, so later keyframe corrections (BA) move it too.
struct FrameRecord {
  double timestamp = 0;
  KeyFramePtr reference;
  Eigen::Isometry3d T_c_ref = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d live_T_cw = Eigen::Isometry3d::Identity();  // as tracking gave it: what the final pose is checked by
  bool tracked = false;
  bool placed_back = false;  // lost when tracked, placed afterwards from a later fix along the lost-frame chain
};

class Tracker {
 public:
  Tracker(const SlamConfig& cfg, const PinholeCamera& camera, double close_depth, Map& map, KeyframeSink& sink);

  TrackOutcome track(const RgbdFrame& input);
  void set_keypoint_filter(KeypointFilterFn fn) { filter_ = std::move(fn); }
  void set_extraction_mask(ExtractionMaskFn fn) { extraction_mask_ = std::move(fn); }
  /// Keyframes to relocalize against when tracking is lost (none: only the last reference's neighbourhood).
  void set_place_database(const KeyframeDatabase* places) { places_ = places; }

  /// Before the first frame, on a loaded map: the first frames relocalize in it (no new segment until
  /// relocalization.loaded_map_patience frames failed); frame ids continue after the map's.
  void start_in_loaded_map(long next_frame_id, int segments);
  /// Localization only: track against the map without adding keyframes or points, and never start a new segment
  /// (a lost frame stays lost until relocalization finds it). May be switched at any frame.
  void set_localization_only(bool on) {
    localization_only_ = on;
    lost_chain_.clear();  // frames chained before the switch are not placed back after it
  }
  bool localization_only() const { return localization_only_; }
  /// Where the caller says the camera is (world frame, e.g. from odometry or a click on the map): while not tracking,
  /// relocalization tries the keyframes within `radius_m` of it first and keeps a fix only within `radius_m`. Kept
  /// until a frame is tracked.
  void set_pose_hint(const Eigen::Isometry3d& T_wc, double radius_m) { pose_hint_ = PoseHint{T_wc, radius_m}; }
  long next_frame_id() const { return next_frame_id_; }

  TrackState state() const { return state_; }
  const std::vector<FrameRecord>& records() const { return records_; }
  const Frame& last_frame() const { return last_; }
  int segments() const { return segments_; }
  int relocalizations() const { return relocalizations_; }
  /// Frames lost when tracked and placed afterwards from a later fix (FrameRecord::placed_back).
  int placed_back_frames() const { return placed_back_; }
  /// Pose solves the near-mover check changed (a frame can count more than once: motion model, then local map).
  long near_mover_frames() const { return near_mover_frames_; }
  std::shared_ptr<const ScaleInfo> scale() const { return scale_; }

 private:
  Frame build_frame(const RgbdFrame& input, FrameTimings& t);
  /// Rolling-shutter compensation of `f` (the frame being tracked) with the camera motion `motion` over `dt`.
  void compensate_with(FrameFeatures& f, const Eigen::Isometry3d& motion, double dt) const;
  /// After the local-map solve: compensates the frame's keypoints again with the motion that solve measured
  /// (last frame to this one) and solves the pose alone again on that solve's inliers.
  void refine_rolling_shutter(Frame& cur, FrameTimings& t);
  /// How tracking solves a frame's pose (kernel, solver, the pose observer).
  optim::PoseOptimConfig pose_config() const;
  bool initialize(Frame& cur, const Eigen::Isometry3d& T_cw);
  void refresh_last_frame(long frame_id);
  static void record_fates(const Frame& cur, TrackOutcome& out);
  static PoseResiduals inlier_residuals(const Frame& cur, const PinholeCamera& camera);
  /// Motion model, falling back to (or cross-checked by) the reference keyframe; true when tracked.
  bool track_initial_pose(Frame& cur, FrameTimings& t);
  /// Both return the inliers after pose optimisation (0 when too few matches to optimise).
  int track_motion_model(Frame& cur, FrameTimings& t, int* matches);
  int track_reference_keyframe(Frame& cur, const KeyFramePtr& kf, FrameTimings& t);
  bool recover(Frame& cur, FrameTimings& t);
  /// Global relocalization: place candidates from the database, each located by descriptor matches + RANSAC.
  bool relocalize(Frame& cur, FrameTimings& t);
  /// A lost frame in a map this session did not build joins the lost-frame chain (chain_step_ says how).
  void chain_lost_frame(const Frame& cur, FrameTimings& t);
  bool relocalize_near_hint(Frame& cur);
  /// A map this session did not build (a loaded map before its first fix, or localization only): the frame is often
  /// between mapped viewpoints, so relocalization asks less of one keyframe and the local map verifies.
  bool in_foreign_map() const { return awaiting_loaded_map_ || localization_only_; }
  /// locate_against_points() on `kf` and its best covisibles; adds their ids to `tried` (matched once per frame).
  int locate_in_neighbourhood(Frame& cur, const KeyFrame& kf, const LocalizationConfig& lc,
                              std::unordered_set<long>& tried) const;
  void accept_relocalization(Frame& cur, const KeyFramePtr& kf, int inliers, int score);
  /// Relocalization of the views chained while lost (slam/lost_frame_chain.hpp), matched together against the
  /// candidates' neighbourhoods; the frame's own matches at the pose found then decide.
  bool locate_lost_views(Frame& cur, const std::vector<PlaceCandidate>& candidates, const LocalizationConfig& lc);
  /// After a fix, the frames chained while lost get their poses back from it (FrameRecord::placed_back).
  void place_back_chained_frames(const Frame& cur);
  bool track_local_map(Frame& cur, FrameTimings& t);
  int optimize_and_discard(Frame& cur, FrameTimings& t);
  /// The near-mover check (slam/near_mover.hpp) on a solved frame: when the near matches move against the far
  /// ones, solves again without them and marks them (and the keypoints on the mover) so nothing is built on them.
  void drop_near_mover(Frame& cur, const FramePoseProblem& p, const optim::PoseOptimConfig& pc,
                       const std::vector<bool>* young, optim::PoseOptimResult& res);
  /// Solves T_cw on the matches of `p` not `left_out`; the result is per match of `p`, the left-out ones outliers.
  optim::PoseOptimResult solve_leaving_out(Eigen::Isometry3d& T_cw, const FramePoseProblem& p,
                                           const optim::PoseOptimConfig& pc, const std::vector<bool>& left_out,
                                           const std::vector<bool>* young) const;
  /// Solves cur.T_cw on the matches that are not suspects; the suspects are then tested at that pose.
  optim::PoseOptimResult solve_without_suspects(Frame& cur, const FramePoseProblem& p, const optim::PoseOptimConfig& pc,
                                                const std::vector<bool>& suspect, const std::vector<bool>* young) const;
  /// The matches of `p` that may lie on the mover being followed; empty when none is followed.
  std::vector<bool> mover_suspects(const Frame& cur, const FramePoseProblem& p) const;
  /// After a pose solve that left the suspects out first: those that miss the pose confirm the mover (it moves on,
  /// its points are marked moving) and carry its region along; the keypoints on it build nothing.
  void follow_mover(Frame& cur, const FramePoseProblem& p, const std::vector<bool>& suspect,
                    const optim::PoseOptimResult& res);
  /// Marks the keypoints the followed mover covers (cur.on_mover): no map point or depth point is made on them.
  void mark_mover_keypoints(Frame& cur) const;
  void update_local_map(Frame& cur);
  bool need_keyframe(const Frame& cur, int inliers) const;
  void create_keyframe(Frame& cur);
  KeyFramePtr insert_keyframe_with_depth_points(Frame& cur, bool all_depth_points);
  void clean_temporary_matches(Frame& cur);
  void record(const Frame& cur, bool tracked);

  SlamConfig cfg_;
  PinholeCamera camera_;
  double close_depth_;
  Map& map_;
  KeyframeSink& sink_;
  std::unique_ptr<FeatureExtractor> extractor_;
  std::shared_ptr<const ScaleInfo> scale_;
  KeypointFilterFn filter_;
  ExtractionMaskFn extraction_mask_;
  const KeyframeDatabase* places_ = nullptr;

  TrackState state_ = TrackState::NotInitialized;
  long next_frame_id_ = 0;
  Frame last_;
  Eigen::Isometry3d last_T_c_ref_ = Eigen::Isometry3d::Identity();
  bool last_is_keyframe_ = false;
  Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();
  bool has_velocity_ = false;
  double velocity_dt_ = 0;  // seconds velocity_ spans (0: not measured between two tracked frames)
  KeyFramePtr reference_kf_;
  long last_kf_frame_id_ = 0;
  long last_recovery_frame_id_ = -1000;
  int lost_count_ = 0;
  int segments_ = 0;
  bool awaiting_loaded_map_ = false;  // started on a loaded map and not relocalized in it yet
  bool localization_only_ = false;
  int relocalizations_ = 0;
  int placed_back_ = 0;
  long near_mover_frames_ = 0;
  struct ShutterSource {
    std::shared_ptr<const FrameFeatures> features;  // the frame being tracked, before compensation
    std::vector<float> sensor_rows;                 // its keypoints' rows on the sensor
    int image_rows = 0;
  } shutter_source_;  // kept only with tracking.rolling_shutter_s > 0
  MoverTrack mover_track_;  // the near mover being followed (slam/mover_track.hpp)
  LostFrameChain lost_chain_;  // the frames since the loss, in a map this session did not build
  LostFrameChain::Added chain_step_;  // what adding the frame being tracked did to the chain
  bool fix_in_foreign_map_ = false;   // the last recovery was in a map this session did not build
  struct PoseHint {
    Eigen::Isometry3d T_wc;
    double radius_m;
  };
  std::optional<PoseHint> pose_hint_;
  std::optional<Relocalization> relocalized_;  // of the frame being tracked, moved into its TrackOutcome
  long seen_corrections_ = 0;  // map_.corrections() when the last frame was last re-anchored
  std::vector<KeyFramePtr> local_keyframes_;
  std::vector<MapPointPtr> local_points_;
  std::vector<FrameRecord> records_;
};

}  // namespace varslam::slam
