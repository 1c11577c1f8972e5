#pragma once
// Choosing which detected corners to keep so they cover the image instead of clustering on the
// strongest texture.
#include <opencv2/core.hpp>
#include <vector>

namespace varslam {

/// Keeps at most `budget` of `candidates` (all inside `region`), spread evenly: the region is cut into
/// about `budget` square cells and the cells are visited round-robin, each giving up its strongest
/// remaining corner per round; within the last, partial round the strongest corners win.
/// Deterministic: ties are broken by position. Returns the kept corners in round order.
std::vector<cv::KeyPoint> spread_keypoints(const std::vector<cv::KeyPoint>& candidates, const cv::Rect& region,
                                           int budget);

}  // namespace varslam
