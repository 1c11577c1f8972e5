#pragma once
// Which pixels of a keyframe the dense map must not build surface from: everything the system knows moved.
//  - people: inside each (enlarged) person box, the pixels up to the far end of the person's depth band (the person
//    filter's band: a wrong depth mode then still covers the person) and those without depth; a box whose person
//    depth is unknown is left out whole;
//  - the near mover tracking follows (a carried box): its image region grown by a margin, at its depth band;
//  - keypoints flagged moving (on the near mover, or outliers of the pose solve): a disc around each at its depth;
//  - the caller's own mover mask.
// Pixels behind a mover (the room seen past a person) stay in. The result is dilated by `margin_px` so the mixed
// depths at a mover's outline go too.
#include <opencv2/core.hpp>
#include <vector>

namespace varslam::dense {

struct PersonBand {
  cv::Rect rect;            // enlarged box, clipped to the image
  float depth_m = 0;        // 0 = unknown
  float band_m = 0.5f;      // pixels nearer than depth_m + band_m are left out
};

struct NearMoverBand {
  cv::Rect2f region;
  float near_m = 0, far_m = 0, depth_margin = 0.15f;  // band [near (1 - margin), far (1 + margin)]
  float margin_px = 10;
};

struct MovingPoint {
  cv::Point2f px;
  float depth_m = 0;  // 0: the disc is left out at every depth
};

struct MoverMaskInputs {
  std::vector<PersonBand> people;
  std::vector<NearMoverBand> near_movers;
  std::vector<MovingPoint> moving_points;
  float point_radius_px = 12;
  cv::Mat caller_mask;  // CV_8UC1, non-zero = mover; may be empty
  int margin_px = 3;

  /// Names no mover: the mask would be all zero.
  bool names_nothing() const {
    return people.empty() && near_movers.empty() && moving_points.empty() && caller_mask.empty();
  }
};

/// CV_8UC1 of depth's size, 255 where a mover is. `depth`: CV_32FC1 metres (0 = none).
cv::Mat mover_mask(const cv::Mat& depth, const MoverMaskInputs& in);

}  // namespace varslam::dense
