#include "features/opencv_orb_extractor.hpp"

#include <opencv2/imgproc.hpp>

namespace varslam {
namespace {
constexpr int kPatchSize = 31;
constexpr int kEdgeThreshold = 31;  // cv::ORB's default; it needs edge >= patch size
}  // namespace

OpenCvOrbExtractor::OpenCvOrbExtractor(const OrbParams& params)
    : FeatureExtractor(params),
      orb_(cv::ORB::create(params.n_features, static_cast<float>(params.scale_factor), params.n_levels,
                           kEdgeThreshold, 0, 2, cv::ORB::HARRIS_SCORE, kPatchSize, params.ini_th_fast)) {}

void OpenCvOrbExtractor::do_extract(const cv::Mat& gray, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors,
                                    const cv::Mat& mask) {
  keypoints.clear();
  descriptors.create(0, 32, CV_8UC1);
  // cv::ORB asserts on images too small for its border; there is nothing to find in them anyway.
  if (gray.empty() || gray.cols <= 2 * kEdgeThreshold || gray.rows <= 2 * kEdgeThreshold) return;
  cv::Mat input = gray;
  if (gray.type() == CV_8UC3) cv::cvtColor(gray, input, cv::COLOR_BGR2GRAY);
  CV_Assert(input.type() == CV_8UC1);
  orb_->detectAndCompute(input, mask, keypoints, descriptors);  // an empty mask allows everything
  if (descriptors.empty()) descriptors.create(0, 32, CV_8UC1);
}

}  // namespace varslam
