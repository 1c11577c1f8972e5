#pragma once
// Deterministic synthetic images for the feature tests.
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace varslam::testing {

/// Random filled shapes at random grey levels: many corners of all orientations, everywhere.
/// `contrast` scales the grey-level spread around mid-grey (1 = full range).
inline cv::Mat textured_image(int width, int height, std::uint64_t seed = 7, double contrast = 1.0) {
  cv::RNG rng(seed);
  cv::Mat img(height, width, CV_8UC1, cv::Scalar(128));
  const auto grey = [&] { return cv::Scalar(128 + contrast * (rng.uniform(0, 256) - 128)); };
  const int shapes = width * height / 300;
  for (int i = 0; i < shapes; ++i) {
    const cv::Point c(rng.uniform(0, width), rng.uniform(0, height));
    const int s = rng.uniform(3, 18);
    switch (rng.uniform(0, 3)) {
      case 0: {
        const cv::RotatedRect box(c, cv::Size2f(float(s), float(rng.uniform(3, 18))), float(rng.uniform(0, 180)));
        cv::Point2f p[4];
        box.points(p);
        const cv::Point q[4] = {p[0], p[1], p[2], p[3]};
        cv::fillConvexPoly(img, q, 4, grey(), cv::LINE_AA);
        break;
      }
      case 1: {
        const cv::Point tri[3] = {c, c + cv::Point(rng.uniform(-s, s), s), c + cv::Point(s, rng.uniform(-s, s))};
        cv::fillConvexPoly(img, tri, 3, grey(), cv::LINE_AA);
        break;
      }
      default:
        cv::circle(img, c, s / 2 + 1, grey(), cv::FILLED, cv::LINE_AA);
    }
  }
  cv::GaussianBlur(img, img, cv::Size(3, 3), 0.8);
  return img;
}

}  // namespace varslam::testing
