#pragma once
// Binary-descriptor utilities: Hamming distance, brute-force matching, rotation consistency, medoid.
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace varslam {

inline constexpr int kDescriptorBytes = 32;  // 256-bit ORB descriptor

/// Hamming distance of two 32-byte descriptors (popcount on 64-bit words).
/// a, b: 1x32 CV_8U rows (throws std::invalid_argument otherwise).
int descriptor_distance(const cv::Mat& a, const cv::Mat& b);
int descriptor_distance(const std::uint8_t* a, const std::uint8_t* b);

struct DescriptorMatch {
  int query;     // row in the query descriptors
  int train;     // row in the train descriptors
  int distance;  // Hamming distance
};

/// Brute-force matching of every query row against all train rows (both Nx32 CV_8U).
/// A match is kept when its distance is <= max_distance and, if there is a second-best train row,
/// best < ratio * second_best (Lowe's ratio test; ratio >= 1 disables it). With `unique`, each train row
/// keeps only its best query (lowest distance, then lowest query index). Result sorted by query index.
/// For the rotation-consistency check, compute angle differences of the matches and use rotation_consistent.
std::vector<DescriptorMatch> match_descriptors(const cv::Mat& query, const cv::Mat& train, int max_distance,
                                               double ratio, bool unique);

/// Rotation consistency: keep matches whose keypoint angle difference falls in the 3 most populated of 30 bins
/// (12 degrees each, differences taken modulo 360). Returns the kept indices in increasing order.
std::vector<int> rotation_consistent(const std::vector<float>& angle_differences_deg);

/// Representative descriptor of a set: the one with least median distance to the others.
/// Returns its index, or -1 for an empty set. Ties go to the lowest index.
int medoid_descriptor(const std::vector<cv::Mat>& descriptors);

}  // namespace varslam
