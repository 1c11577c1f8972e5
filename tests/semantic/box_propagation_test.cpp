#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "semantic/box_propagation.hpp"

namespace varslam::semantic {
namespace {

cv::Mat texture(cv::Size size, int seed) {
  cv::Mat noise(size, CV_8UC1);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(noise, noise, cv::Size(5, 5), 1.5);
  return noise;
}

// Static textured background with a differently textured "person" patch pasted at `at`.
cv::Mat scene(const cv::Mat& background, const cv::Mat& person, cv::Point at) {
  cv::Mat img = background.clone();
  person.copyTo(img(cv::Rect(at, person.size())));
  return img;
}

Detections one_box(cv::Rect2f r) {
  Detection d;
  d.timestamp = 3.0;
  d.label = "person";
  d.box = r;
  return {d};
}

TEST(BoxPropagation, FollowsAPersonMovingOverAStaticBackground) {
  const cv::Mat bg = texture({640, 480}, 1), person = texture({90, 200}, 2);
  const cv::Mat old_gray = scene(bg, person, {200, 120});
  const cv::Mat cur_gray = scene(bg, person, {212, 115});  // the person moved by (+12, -5)
  // The detection box is a bit larger than the person, as detector boxes are.
  const Detections moved = propagate_boxes(one_box({190, 110, 110, 220}), old_gray, cur_gray);
  ASSERT_EQ(moved.size(), 1u);
  EXPECT_NEAR(moved[0].box.x, 202.f, 0.5f);
  EXPECT_NEAR(moved[0].box.y, 105.f, 0.5f);
  EXPECT_FLOAT_EQ(moved[0].box.width, 110.f);
  EXPECT_FLOAT_EQ(moved[0].box.height, 220.f);
  EXPECT_DOUBLE_EQ(moved[0].timestamp, 3.0);  // still says which image it was detected in
}

TEST(BoxPropagation, FollowsAWholeImageShift) {
  const cv::Mat old_gray = texture({320, 240}, 3);
  cv::Mat cur_gray;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -6, 0, 1, 4);
  cv::warpAffine(old_gray, cur_gray, shift, old_gray.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  const Detections moved = propagate_boxes(one_box({100, 60, 80, 120}), old_gray, cur_gray);
  EXPECT_NEAR(moved[0].box.x, 94.f, 0.5f);
  EXPECT_NEAR(moved[0].box.y, 64.f, 0.5f);
}

TEST(BoxPropagation, KeepsBoxesWhenFlowFails) {
  const cv::Mat flat(240, 320, CV_8UC1, cv::Scalar(100));  // no corners to track
  const Detections boxes = one_box({50, 50, 60, 100});
  EXPECT_EQ(propagate_boxes(boxes, flat, flat)[0].box, boxes[0].box);
  // Mismatched images: unchanged rather than a crash.
  EXPECT_EQ(propagate_boxes(boxes, texture({320, 240}, 4), cv::Mat())[0].box, boxes[0].box);
  EXPECT_TRUE(propagate_boxes({}, flat, flat).empty());
}

}  // namespace
}  // namespace varslam::semantic
