#pragma once
// Maps that outlive a run: the keyframes, map points, covisibility graph and
// spanning tree, place signatures and map segments, with the camera and
// settings they were built with. docs/map_format.md describes the file: an
// 8-byte magic, then CBOR (nlohmann-json) holding the format version, a CRC-32
// of the content and the content.
//
// This module is the file alone (plain records <-> bytes), so the reader can be
// fuzzed on its own; the live map is turned into records and back by
// slam/map_snapshot.hpp:
//   snapshot_map (live map -> SavedMap) -> encode_map (-> bytes);   decode_map
//   (bytes -> SavedMap, fully checked)
//   -> restore_map (SavedMap -> live map).
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/camera.hpp"

namespace varslam::mapfile {

inline constexpr int kMapFormatVersion = 1;
inline constexpr char kMapMagic[8] = {'V', 'S', 'L', 'A', 'M', 'M', 'A', 'P'};

/// What a map was built with: a map is only usable with the same camera and the
/// same scale pyramid.
struct MapFingerprint {
  PinholeCamera camera;  // the colour camera (after depth registration)
  int n_levels = 8;
  double scale_factor = 1.2;
  double close_depth = 3.0;
  double disparity_weight = 0.0;
  std::string settings_yaml;  // the whole settings document, for the record
  std::string created_by;     // "varslam <version>"
};

struct SavedKeyframe {
  long id = 0, frame_id = 0;
  double timestamp = 0;
  int segment = 1;
  Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
  std::vector<cv::KeyPoint> keypoints;            // undistorted, octave = pyramid level
  std::vector<float> depth;                       // metres, <= 0 without depth
  cv::Mat descriptors;                            // N x 32 CV_8U
  std::vector<std::pair<int, long>> points;       // keypoint index -> map point id
  long parent = -1;                               // spanning tree (-1: a root)
  std::vector<std::pair<long, int>> connections;  // covisibility: keyframe id -> weight
  cv::Mat signature;                              // place-recognition descriptors (K x 32 CV_8U)
};

struct SavedMapPoint {
  long id = 0, first_keyframe_id = 0, first_frame_id = 0, reference_keyframe = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero();
  cv::Mat descriptor;  // 1 x 32 CV_8U
  double min_distance = 0, max_distance = 0;
  int visible = 1, found = 1;
  std::vector<std::pair<long, int>> observations;  // keyframe id -> keypoint index
};

struct SavedMap {
  MapFingerprint fingerprint;
  std::vector<SavedKeyframe> keyframes;   // by id
  std::vector<SavedMapPoint> map_points;  // by id
  long next_keyframe_id = 0, next_map_point_id = 0, next_frame_id = 0;
  /// The map's own alignment to ground truth (map frame -> ground-truth frame),
  /// when the run that built it had ground truth: localization runs in this map
  /// are evaluated through it, not through a fresh alignment.
  std::optional<Eigen::Isometry3d> groundtruth_alignment;
};

std::string encode_map(const SavedMap& map);
/// Throws InputError naming `what` (the file) on anything but a well-formed map
/// of this format version: not a map, another version, truncated or corrupted
/// (checksum), a missing or ill-typed field, dangling references.
SavedMap decode_map(const std::string& bytes, const std::string& what);

/// Writes atomically (temp file + rename).
void save_map_file(const SavedMap& map, const std::filesystem::path& file);
SavedMap load_map_file(const std::filesystem::path& file);

/// Largest relative difference of two cameras' intrinsics (fx, fy against fx, fy; cx, cy against width, height).
double intrinsics_difference(const PinholeCamera& a, const PinholeCamera& b);

/// InputError when the map was built with another camera (size, or intrinsics beyond 10 %: another sensor, not a
/// recalibration) or scale pyramid. Between 1 and 10 % it warns: the caller's intrinsics are used.
void check_map_compatible(const MapFingerprint& map, const PinholeCamera& camera, int n_levels, double scale_factor,
                          const std::string& what);

}  // namespace varslam::mapfile
