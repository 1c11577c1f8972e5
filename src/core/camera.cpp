#include "core/camera.hpp"

namespace varslam {

cv::Mat PinholeCamera::K() const {
  return (cv::Mat_<double>(3, 3) << fx, 0, cx, 0, fy, cy, 0, 0, 1);
}

cv::Mat PinholeCamera::dist_coeffs() const { return (cv::Mat_<double>(1, 5) << k1, k2, p1, p2, k3); }

}  // namespace varslam
