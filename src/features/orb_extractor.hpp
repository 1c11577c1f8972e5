#pragma once
// Our ORB extractor: pyramid, FAST on a cell grid with a fallback threshold, evenly spread keypoints,
// intensity-centroid orientation, rotated BRIEF on the blurred level. Deterministic.
#include <opencv2/core.hpp>
#include <vector>

#include "features/feature_extractor.hpp"
#include "features/orb_descriptor.hpp"

namespace varslam {

class OrbExtractor final : public FeatureExtractor {
 public:
  explicit OrbExtractor(const OrbParams& params);

  /// Keypoint budget of each level, proportional to its area (a geometric series of ratio 1/scale^2) and
  /// summing to n_features. Levels that cannot fill theirs pass the rest on to the next level.
  const std::vector<int>& level_budgets() const { return budgets_; }

  /// Keypoint centres keep this many pixels from the border of their level: the orientation patch and the
  /// rotated BRIEF pattern (radius 15) then stay inside the image.
  static constexpr int kEdge = kOrbPatchRadius + 1;
  static constexpr int kGridCell = 30;  // FAST grid cell side [px]

 private:
  void do_extract(const cv::Mat& gray, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors,
                  const cv::Mat& mask) override;
  struct LevelKeypoint {
    int x, y;  // integer pixel at the level
    float angle;
    float response;
  };

  std::vector<int> budgets_;
  CentroidOrientation orientation_;
  // Buffers kept across frames so a steady stream of same-size images allocates nothing new.
  std::vector<cv::Mat> pyramid_;
  std::vector<cv::Mat> smoothed_;
  std::vector<std::vector<LevelKeypoint>> level_keypoints_;
  std::vector<cv::KeyPoint> candidates_;
  cv::Mat gray_buffer_;
};

}  // namespace varslam
