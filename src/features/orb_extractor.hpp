#pragma once
// Our ORB extractor: pyramid, FAST on a cell grid with a fallback threshold, evenly spread keypoints,
// intensity-centroid orientation, rotated BRIEF on the blurred level. Deterministic.
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/task_pool.hpp"

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
  // The two halves of a level's work, each independent of the other levels: the corners it offers, then the
  // keypoints and descriptors of its share of the budget. Only the budgets pass from level to level.
  void find_corners(int level, const cv::Mat& mask, cv::Size base);
  void describe_level(int level, cv::Size base, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors) const;
  cv::Rect level_region(int level) const;

  std::vector<int> budgets_;
  CentroidOrientation orientation_;
  std::unique_ptr<TaskPool> pool_;  // null for one thread
  // Buffers kept across frames so a steady stream of same-size images allocates nothing new; one per level.
  std::vector<cv::Mat> pyramid_;
  std::vector<cv::Mat> smoothed_;
  std::vector<std::vector<cv::KeyPoint>> candidates_;
  std::vector<int> level_budget_, level_kept_, first_row_;
  cv::Mat gray_buffer_;
};

}  // namespace varslam
