#pragma once
// Depth-aware semantic keypoint filter (DESIGN.md section 3): inside each person box, only keypoints at the
// person's depth are dynamic; the background seen past the person is kept.
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <vector>

#include "core/detection.hpp"

namespace varslam::semantic {

struct FilterConfig {
  float box_enlarge = 0.1f;    // fraction of width/height added on each side of a box
  float depth_band_m = 0.5f;   // keypoints within +-band of the person depth are dynamic
  float min_depth_m = 0.1f;    // depths outside [min, max] count as invalid
  float max_depth_m = 20.0f;
  float bin_m = 0.1f;          // histogram bin width for the person-depth mode
  // A near histogram peak is "strong" when it holds at least this fraction of the box's valid depths.
  float peak_fraction = 0.15f;
  int sample_step = 2;         // depth samples every n-th pixel inside a box (cost vs. accuracy)
};

struct FilterStats {
  int in_boxes = 0;          // keypoints inside at least one (enlarged) box
  int dropped = 0;           // all removed keypoints (person depth + no depth)
  int kept_background = 0;   // inside a box but clearly behind the person
  int dropped_no_depth = 0;  // inside a box without a valid depth
  int kept_in_front = 0;     // inside a box but clearly nearer than the person (an occluder, e.g. a desk)
};

/// Person depth inside `roi` of depth_m (CV_32FC1, metres, 0 = invalid): the nearest strong mode of a depth
/// histogram. Returns 0 when the box has no valid depth.
float estimate_person_depth(const cv::Mat& depth_m, const cv::Rect& roi, const FilterConfig& cfg);

/// keep[i] for each keypoint. Inside a box: drop if |d - person| <= band or d has no valid depth; keep if
/// d > person + band (background). Keypoints nearer than person - band are occluders in front of the person and
/// are kept. Outside all boxes: keep. depth_m may be empty (then every keypoint in a box counts as no-depth).
std::vector<bool> filter_keypoints(const std::vector<cv::KeyPoint>& kps, const cv::Mat& depth_m,
                                   const Detections& boxes, const FilterConfig& cfg, FilterStats* stats = nullptr);

/// Box enlarged by `fraction` of its size per side and clipped to the image.
cv::Rect enlarge_box(const cv::Rect2f& box, float fraction, const cv::Size& image_size);

}  // namespace varslam::semantic
