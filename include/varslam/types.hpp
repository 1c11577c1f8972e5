#pragma once
// The plain value types of varslam's public API (C++17, no Eigen, Ceres or internal classes).
//
// Conventions
// - Camera frame: OpenCV's (and ROS's optical frame): x right, y down, z forward along the optical axis.
// - World frame: the camera frame of the first tracked frame of the first map segment (a loaded map keeps its own).
//   Tracking lost and found again in a new segment keeps the world frame once a loop joins the segments; until then
//   the new segment is placed where the last one ended.
// - Pose: camera-to-world, p_world = R * p_camera + t; metres; rotation as a unit quaternion (x, y, z, w).
// - Timestamps: seconds, as the caller gives them; strictly increasing from frame to frame, finite.
// - Images: colour CV_8UC3 BGR (or CV_8UC1 gray), depth CV_16UC1 raw units (divided by `depth.factor`) or CV_32FC1
//   metres, 0 = no depth, both of the camera's size. Pixel coordinates: (0, 0) is the centre of the top-left pixel.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace varslam {

struct Pose {
  std::array<double, 3> translation{0, 0, 0};  // metres, the camera centre in the world
  std::array<double, 4> rotation{0, 0, 0, 1};  // unit quaternion x, y, z, w (camera-to-world)
};

struct TimedPose {
  double timestamp = 0;
  Pose pose;
};

enum class TrackingState {
  NotInitialized,  // no map yet (or, with a loaded map, not yet relocalized in it)
  Tracking,        // the frame has a pose
  Lost,            // no pose; the next frames relocalize or start a new map segment
};

/// A person in the image, from the caller's own detector: the box in pixels.
struct PersonBox {
  float x = 0, y = 0, width = 0, height = 0;
  float score = 1;
};

/// One frame through tracking: what Slam::track() returns.
struct TrackedFrame {
  std::size_t index = 0;  // frames given to this session before this one
  double timestamp = 0;
  TrackingState state = TrackingState::NotInitialized;
  std::optional<Pose> pose;  // camera-to-world as tracking gave it; empty when not tracked
  bool keyframe = false;     // the frame became a keyframe (id below)
  long keyframe_id = -1;
  bool new_segment = false;  // tracking had been lost and a new map segment starts here
  bool relocalized = false;  // found its place in the map again (after a loss, or in a loaded map)
  int keypoints = 0, inliers = 0;
  std::size_t map_keyframes = 0, map_points = 0;
  double tracking_ms = 0;  // time tracking took on this frame
};

struct MapPointInfo {
  long id = 0;
  std::array<double, 3> position{0, 0, 0};  // world frame, metres
  int observations = 0;                     // keyframes that see it
};

struct KeyframeInfo {
  long id = 0;
  double timestamp = 0;
  Pose pose;  // camera-to-world, after every correction so far
};

/// A consistent copy of the map at one moment: it does not change after it is handed out.
struct MapSnapshot {
  std::size_t frame_index = 0;  // frames tracked when it was taken
  std::vector<KeyframeInfo> keyframes;
  std::vector<MapPointInfo> points;
};

/// The dense map of the static scene (settings `dense.enabled`): what the keyframes' depth shows of the scene, the
/// movers left out. A copy: it does not change after it is handed out.
struct DenseMapSnapshot {
  double voxel_size = 0;        // metres
  std::size_t keyframes = 0;    // keyframes fused into it
  std::vector<std::array<float, 3>> vertices;          // mesh, world frame, metres
  std::vector<std::array<std::uint8_t, 3>> colours;    // RGB per vertex
  std::vector<std::array<std::int32_t, 3>> triangles;  // vertex indices
  std::vector<std::array<float, 3>> occupied;          // centres of the occupied voxels (the occupancy map)
  std::vector<std::array<float, 3>> free;              // centres of the voxels seen free
  std::vector<std::array<float, 3>> surface;           // points on the surface, thinned (DenseMapRequest)
  std::vector<std::array<std::uint8_t, 3>> surface_colours;  // RGB per surface point
};

/// What Slam::dense_map_snapshot(request) fills in; the rest of the snapshot stays empty. Each part is a pass over
/// the map: ask only for what you use.
struct DenseMapRequest {
  bool mesh = true;       // vertices, colours, triangles
  bool occupancy = true;  // occupied, free
  // surface, surface_colours: the mesh's vertices thinned to one per cube of surface_cell_voxels^3 voxels (1, 2, 4 or
  // 8). Read incrementally: each call reads only what changed since the previous one, a few blocks at a time, so a
  // periodic publisher costs little and never holds the dense map for long.
  bool surface = false;
  int surface_cell_voxels = 2;
};

/// One Local Bundle Adjustment of local mapping, with the shape of Barron's loss it chose.
struct LocalBaInfo {
  long keyframe_id = 0;
  double timestamp = 0;
  double alpha = 2;         // applied shape (after the cap mapping.alpha_max)
  double fitted_alpha = 2;  // fitted to the residuals, before the cap
  int keyframes = 0, points = 0, observations = 0, outliers = 0;
  double ms = 0;
};

/// One closed loop.
struct LoopInfo {
  long query_keyframe = 0, loop_keyframe = 0;
  double timestamp = 0;
  double correction_m = 0, correction_deg = 0;
};

/// The person filter on one frame: the boxes it used (the caller's or its detector's).
struct PersonBoxesInfo {
  std::size_t index = 0;
  double timestamp = 0;
  std::vector<PersonBox> boxes;
  double box_age_s = 0;  // frame time minus the time of the image the boxes were found in
};

}  // namespace varslam
