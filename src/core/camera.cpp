#include "core/camera.hpp"

#include <opencv2/calib3d.hpp>

namespace varslam {

cv::Mat PinholeCamera::K() const {
  return (cv::Mat_<double>(3, 3) << fx, 0, cx, 0, fy, cy, 0, 0, 1);
}

cv::Mat PinholeCamera::dist_coeffs() const { return (cv::Mat_<double>(1, 5) << k1, k2, p1, p2, k3); }

std::vector<cv::Point2f> undistort_pixels(const PinholeCamera& camera, const std::vector<cv::Point2f>& px) {
  std::vector<cv::Point2f> out;
  if (px.empty()) return out;
  const cv::Mat K = camera.K();
  cv::undistortPoints(px, out, K, camera.dist_coeffs(), cv::noArray(), K,
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-3));
  return out;
}

}  // namespace varslam
