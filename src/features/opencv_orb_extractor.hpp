#pragma once
// cv::ORB behind our interface, configured from the same OrbParams (for comparison with ours).
#include <opencv2/features2d.hpp>

#include "features/feature_extractor.hpp"

namespace varslam {

class OpenCvOrbExtractor final : public FeatureExtractor {
 public:
  explicit OpenCvOrbExtractor(const OrbParams& params);

 private:
  void do_extract(const cv::Mat& gray, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors,
                  const cv::Mat& mask) override;
  cv::Ptr<cv::ORB> orb_;
};

}  // namespace varslam
