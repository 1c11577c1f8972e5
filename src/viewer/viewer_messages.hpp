#pragma once
// What the viewer sends, as JSON for server-sent events. Bulky arrays (points, poses, keypoints) travel as
// base64 of little-endian float32 / int32 arrays, which the page reads straight into typed arrays.
// Pure functions of plain views, so the encoding is tested without a pipeline or a server.
#include <Eigen/Geometry>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/trajectory.hpp"
#include "dense/tsdf_volume.hpp"
#include "slam/tracking.hpp"

namespace varslam::viewer {

/// How a keypoint is drawn over the image.
enum class KeypointMark : std::uint8_t {
  Unmatched = 0,
  Inlier = 1,
  Outlier = 2,        // matched, flagged by pose optimisation (kernel weight below its gate)
  PersonDropped = 3,  // removed by the person filter before tracking
};
constexpr std::uint8_t kDepthEdgeBit = 8;  // or-ed into the mark: the depth-edge test dropped its depth

struct MarkedKeypoint {
  float u = 0, v = 0;  // image pixels (distorted, as in the image shown)
  std::uint8_t mark = 0;
};

struct PersonBand {
  cv::Rect box;       // as the filter used it (enlarged, clipped)
  float depth_m = 0;  // the person's depth, 0 = unknown
  float band_m = 0;
};

struct FrameView {
  std::size_t index = 0;
  double timestamp = 0;
  slam::TrackState state = slam::TrackState::NotInitialized;
  bool keyframe = false, new_segment = false;
  int keypoints = 0, inliers = 0, depth_edge_rejected = 0;
  slam::FrameTimings timings;
  double fps = 0;
  std::optional<Eigen::Isometry3d> T_wc;
  std::size_t map_keyframes = 0, map_points = 0;
  std::vector<MarkedKeypoint> marks;
  bool person_filter = false, have_detections = false;
  double box_age_s = 0;
  std::vector<PersonBand> people;
};

// Covisibility edges drawn: keyframes sharing at least this many points (the strong links, as ORB-SLAM's viewer).
constexpr int kDrawnCovisibility = 100;

struct KeyframeView {
  long id = 0;
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
};

struct PointView {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  float first_keyframe = 0;  // id of the keyframe that made it (its age)
  float flagged_share = 0;   // share of its matches pose optimisation flagged as outliers
};

struct MapView {
  std::vector<KeyframeView> keyframes;
  std::vector<PointView> points;
  std::vector<std::pair<long, long>> covisibility, spanning_tree;    // keyframe id pairs
  std::vector<Eigen::Vector3d> live, final_trajectory, groundtruth;  // groundtruth in the map's frame
  bool final = false;                                                // after finish(): the final trajectory and map
};

/// One region of the dense map's layer: its surface points (none: the region is empty now) relative to the region's
/// corner, as int16 x y z triples in steps of `unit` metres (region edge / 8192: a fraction of a millimetre, and room
/// for the points that sit just past the region's far side), and their colours as RGB bytes.
struct DenseRegionView {
  std::string key;                    // names the region (its integer index "i,j,k")
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // the region's first corner, world frame
  double size = 0;                    // the region's edge (m)
  double cell = 0;                    // the points' spacing (m), how large the page draws them
  std::vector<dense::SurfacePoint> points;
};

std::string base64(const void* data, std::size_t bytes);
/// The frame message; `image`: the frame's picture (colour or gray), sent as JPEG at most `max_width` wide.
nlohmann::json frame_message(const FrameView& frame, const cv::Mat& image, int max_width = 640, int jpeg_quality = 75);
nlohmann::json map_message(const MapView& map);
nlohmann::json dense_region_message(const DenseRegionView& region);
/// Camera-to-world poses as float32 x y z triples.
std::vector<Eigen::Vector3d> positions(const Trajectory& trajectory);
/// Ground truth moved into the estimate's frame by the rigid alignment of `estimate` to it; empty when fewer than
/// 3 poses associate.
std::vector<Eigen::Vector3d> groundtruth_in_map_frame(const Trajectory& groundtruth, const Trajectory& estimate);
std::string state_name(slam::TrackState s);

}  // namespace varslam::viewer
