#pragma once
// Depth-aware semantic keypoint filter (DESIGN.md section 3): inside each person box, only keypoints at the
// person's depth are dynamic; the background seen past the person is kept.
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <vector>

#include "core/detection.hpp"
#include "core/setting_keys.hpp"

namespace varslam::semantic {

struct FilterConfig {
  float box_enlarge = static_cast<float>(setting_keys::real_default("semantic.box_enlarge"));    // fraction of width/height added on each side of a box
  float depth_band_m = static_cast<float>(setting_keys::real_default("semantic.depth_band_m"));   // keypoints within +-band of the person depth are dynamic
  float min_depth_m = static_cast<float>(setting_keys::real_default("semantic.min_depth_m"));    // depths outside [min, max] count as invalid
  float max_depth_m = static_cast<float>(setting_keys::real_default("semantic.max_depth_m"));
  float bin_m = static_cast<float>(setting_keys::real_default("semantic.bin_m"));          // histogram bin width for the person-depth mode
  // A near histogram peak is "strong" when it holds at least this fraction of the box's valid depths.
  float peak_fraction = static_cast<float>(setting_keys::real_default("semantic.peak_fraction"));
  int sample_step = setting_keys::int_default("semantic.sample_step");         // depth samples every n-th pixel inside a box (cost vs. accuracy)
  // Background keypoints closer than this (pixels at pyramid level 0, scaled with the keypoint's size) to a pixel
  // at the person's depth are dropped too: a corner on the silhouette moves with the person. 0 = off.
  float silhouette_margin_px = static_cast<float>(setting_keys::real_default("semantic.silhouette_margin_px"));
  // Overlapping boxes: a second person depth from the part of the box no other box covers, when that part holds at
  // least this share of the box's depth samples (the nearer person must not capture the farther one's estimate).
  // 1 = off.
  float min_exclusive_share = static_cast<float>(setting_keys::real_default("semantic.min_exclusive_share"));
};

struct FilterStats {
  int in_boxes = 0;          // keypoints inside at least one (enlarged) box
  int dropped = 0;           // all removed keypoints (person depth + no depth)
  int kept_background = 0;   // inside a box but clearly behind the person
  int dropped_no_depth = 0;  // inside a box without a valid depth
  int kept_in_front = 0;     // inside a box but clearly nearer than the person (an occluder, e.g. a desk)
  int dropped_silhouette = 0;  // off the person's depth but within the silhouette margin (part of `dropped`)
};

/// Person depth inside `roi` of depth_m (CV_32FC1, metres, 0 = invalid): the nearest strong mode of a depth
/// histogram. Returns 0 when the box has no valid depth.
float estimate_person_depth(const cv::Mat& depth_m, const cv::Rect& roi, const FilterConfig& cfg);

/// Same, from the depth samples of `roi` that lie in none of `exclude`; 0 when there are none.
float estimate_person_depth(const cv::Mat& depth_m, const cv::Rect& roi, const std::vector<cv::Rect>& exclude,
                            const FilterConfig& cfg);

/// Candidate person depths of one box (0 = none).
struct PersonDepth {
  float whole_m = 0.0f;  // from the whole box
  // From the part no other box covers, when boxes overlap and that part holds at least cfg.min_exclusive_share of
  // the box's samples: a nearer person overlapping the box captures whole_m, this one still finds the box's own.
  float own_part_m = 0.0f;
  bool matches(float d, float band) const {
    return (whole_m > 0.0f && std::abs(d - whole_m) <= band) || (own_part_m > 0.0f && std::abs(d - own_part_m) <= band);
  }
};

/// PersonDepth of each rect (rects may overlap).
std::vector<PersonDepth> estimate_person_depths(const cv::Mat& depth_m, const std::vector<cv::Rect>& rects,
                                                const FilterConfig& cfg);

/// Distance (pixels) from each pixel of `roi` to the nearest pixel of it whose depth matches `person`
/// (CV_32FC1, roi-sized; large where the roi has no such pixel).
cv::Mat distance_to_person(const cv::Mat& depth_m, const cv::Rect& roi, const PersonDepth& person,
                           const FilterConfig& cfg);

/// The people of one frame as both the filter and the extraction mask see them: each detection's box enlarged and
/// clipped to the image, with its person depth. Computed once per frame and shared by the two.
struct PersonRegions {
  std::vector<cv::Rect> rects;       // enlarged boxes, clipped; empty ones left out
  std::vector<PersonDepth> persons;  // one per rect; whole_m == 0: unknown (the box has no valid depth)
  bool has_depth = false;            // depth_m was usable (CV_32FC1 of the image's size)
};

/// Locates the people of `boxes` on a frame of `image_size` (depth_m may be empty: then no person depth is known).
PersonRegions locate_people(const cv::Size& image_size, const cv::Mat& depth_m, const Detections& boxes,
                            const FilterConfig& cfg);

/// keep[i] for each keypoint. Inside a box: drop if |d - person| <= band or d has no valid depth; keep if
/// d > person + band (background). Keypoints nearer than person - band are occluders in front of the person and
/// are kept unless they lie within the silhouette margin of the person's pixels. Outside all boxes: keep. depth_m may be empty (then every keypoint in a box counts as no-depth).
std::vector<bool> filter_keypoints(const std::vector<cv::KeyPoint>& kps, const cv::Mat& depth_m,
                                   const Detections& boxes, const FilterConfig& cfg, FilterStats* stats = nullptr);
/// Same, on people already located on this frame (depth_m: the one they were located with).
std::vector<bool> filter_keypoints(const std::vector<cv::KeyPoint>& kps, const cv::Mat& depth_m,
                                   const PersonRegions& people, const FilterConfig& cfg, FilterStats* stats = nullptr);

/// Where keypoints are worth extracting: 0 on the pixels filter_keypoints would drop (inside an enlarged box, at
/// the person's depth or without depth), 255 elsewhere; CV_8UC1 of `image_size`. Empty when there are no boxes.
cv::Mat allowed_pixels(const cv::Size& image_size, const cv::Mat& depth_m, const Detections& boxes,
                       const FilterConfig& cfg);
/// Same, on people already located on this frame of `image_size` (depth_m: the one they were located with).
cv::Mat allowed_pixels(const cv::Size& image_size, const cv::Mat& depth_m, const PersonRegions& people,
                       const FilterConfig& cfg);

/// Box enlarged by `fraction` of its size per side and clipped to the image.
cv::Rect enlarge_box(const cv::Rect2f& box, float fraction, const cv::Size& image_size);

}  // namespace varslam::semantic
