#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "semantic/keypoint_filter.hpp"

namespace varslam::semantic {
namespace {

// A 640x480 depth image: wall at 4 m, a person-shaped region (head + torso + legs) at about 1.5 m, and a hole
// (no depth) on the wall inside the person's box.
struct Scene {
  cv::Mat depth{480, 640, CV_32FC1, cv::Scalar(4.0f)};
  cv::Rect2f box{220, 80, 200, 360};  // around the person, with wall visible on both sides
  cv::Rect hole{225, 400, 30, 30};
  Scene() {
    cv::Mat person(depth.size(), CV_8UC1, cv::Scalar(0));
    cv::circle(person, {320, 120}, 30, 255, cv::FILLED);                  // head
    cv::rectangle(person, cv::Rect(280, 150, 80, 150), 255, cv::FILLED);  // torso
    cv::rectangle(person, cv::Rect(285, 300, 28, 135), 255, cv::FILLED);  // legs
    cv::rectangle(person, cv::Rect(327, 300, 28, 135), 255, cv::FILLED);
    // A body is not flat: 1.4 .. 1.6 m across it.
    for (int y = 0; y < depth.rows; ++y)
      for (int x = 0; x < depth.cols; ++x)
        if (person.at<uchar>(y, x)) depth.at<float>(y, x) = 1.4f + 0.2f * static_cast<float>((x + y) % 20) / 20.f;
    depth(hole).setTo(0.0f);
  }
  Detections boxes() const {
    Detection d;
    d.label = "person";
    d.box = box;
    return {d};
  }
};

cv::KeyPoint kp(float x, float y) { return cv::KeyPoint(x, y, 7.f); }

TEST(KeypointFilter, DropsPersonKeepsWallBehindDropsNoDepthKeepsOutside) {
  const Scene scene;
  const std::vector<cv::KeyPoint> kps = {
      kp(320, 120), kp(300, 200), kp(340, 260), kp(300, 400),  // 0-3 person: head, torso, torso, leg
      kp(240, 150), kp(400, 300), kp(320, 420),                 // 4-6 wall inside the box (sides, between legs)
      kp(235, 410), kp(245, 425),                               // 7-8 no depth inside the box
      kp(50, 50), kp(600, 450), kp(100, 300),                   // 9-11 wall outside the box
  };
  cv::Mat depth = scene.depth.clone();
  depth.at<float>(300, 100) = 0.0f;  // kp 11: no depth, but outside every box -> kept
  FilterStats stats;
  const auto keep = filter_keypoints(kps, depth, scene.boxes(), FilterConfig{}, &stats);
  const std::vector<bool> expected = {false, false, false, false, true, true, true, false, false, true, true, true};
  ASSERT_EQ(keep.size(), kps.size());
  for (std::size_t i = 0; i < kps.size(); ++i) EXPECT_EQ(keep[i], expected[i]) << "keypoint " << i;
  EXPECT_EQ(stats.in_boxes, 9);
  EXPECT_EQ(stats.dropped, 6);
  EXPECT_EQ(stats.dropped_no_depth, 2);
  EXPECT_EQ(stats.kept_background, 3);
  EXPECT_EQ(stats.kept_in_front, 0);
}

TEST(KeypointFilter, PersonDepthIsTheNearModeEvenWhenTheWallFillsMostOfTheBox) {
  const Scene scene;
  const FilterConfig cfg;
  const cv::Rect roi = enlarge_box(scene.box, cfg.box_enlarge, scene.depth.size());
  // The wall covers more of the box than the person does; the nearest strong mode is still the person.
  EXPECT_GT(cv::countNonZero(scene.depth(roi) > 3.0f), cv::countNonZero(scene.depth(roi) < 2.0f));
  EXPECT_NEAR(estimate_person_depth(scene.depth, roi, cfg), 1.5f, 0.1f);
}

TEST(KeypointFilter, FlyingPixelsNearerThanThePersonDoNotMakeAMode) {
  Scene scene;
  scene.depth(cv::Rect(230, 90, 12, 12)).setTo(0.6f);  // a few stray near pixels (about 0.3% of the box)
  const FilterConfig cfg;
  const cv::Rect roi = enlarge_box(scene.box, cfg.box_enlarge, scene.depth.size());
  EXPECT_NEAR(estimate_person_depth(scene.depth, roi, cfg), 1.5f, 0.1f);
  // A keypoint on those pixels is in front of the person: an occluder, kept.
  FilterStats stats;
  const auto keep = filter_keypoints({kp(236, 96)}, scene.depth, scene.boxes(), cfg, &stats);
  EXPECT_TRUE(keep[0]);
  EXPECT_EQ(stats.kept_in_front, 1);
}

TEST(KeypointFilter, BoxWithoutDepthDropsEverythingInside) {
  const Scene scene;
  const cv::Mat no_depth(scene.depth.size(), CV_32FC1, cv::Scalar(0.0f));
  const std::vector<cv::KeyPoint> kps = {kp(320, 200), kp(240, 150), kp(10, 10)};
  FilterStats stats;
  auto keep = filter_keypoints(kps, no_depth, scene.boxes(), FilterConfig{}, &stats);
  EXPECT_EQ(keep, (std::vector<bool>{false, false, true}));
  EXPECT_EQ(stats.dropped_no_depth, 2);
  keep = filter_keypoints(kps, cv::Mat(), scene.boxes(), FilterConfig{});  // no depth image at all
  EXPECT_EQ(keep, (std::vector<bool>{false, false, true}));
}

TEST(KeypointFilter, EnlargedBoxCatchesPersonPixelsJustOutsideTheDetection) {
  Scene scene;
  scene.depth(cv::Rect(420, 200, 15, 20)).setTo(1.5f);  // an arm sticking out of the detected box
  const std::vector<cv::KeyPoint> kps = {kp(428, 210)};
  FilterConfig cfg;
  EXPECT_FALSE(filter_keypoints(kps, scene.depth, scene.boxes(), cfg)[0]);
  cfg.box_enlarge = 0.0f;
  EXPECT_TRUE(filter_keypoints(kps, scene.depth, scene.boxes(), cfg)[0]);
}

TEST(KeypointFilter, NoBoxesKeepsAll) {
  const Scene scene;
  FilterStats stats;
  stats.dropped = 99;
  const auto keep = filter_keypoints({kp(320, 200), kp(1, 1)}, scene.depth, {}, FilterConfig{}, &stats);
  EXPECT_EQ(keep, (std::vector<bool>{true, true}));
  EXPECT_EQ(stats.dropped, 0);
  EXPECT_EQ(stats.in_boxes, 0);
}

TEST(KeypointFilter, DepthBandDecidesWhatIsThePerson) {
  // Wall at 2.2 m, person at 1.5 m: with a 0.5 m band the wall is background, with 1 m it counts as the person.
  Scene scene;
  scene.depth.setTo(2.2f, scene.depth > 3.0f);
  const std::vector<cv::KeyPoint> kps = {kp(240, 150)};
  FilterConfig cfg;
  EXPECT_TRUE(filter_keypoints(kps, scene.depth, scene.boxes(), cfg)[0]);
  cfg.depth_band_m = 1.0f;
  EXPECT_FALSE(filter_keypoints(kps, scene.depth, scene.boxes(), cfg)[0]);
}

TEST(KeypointFilter, EnlargeBoxClipsToTheImage) {
  EXPECT_EQ(enlarge_box({10, 10, 100, 50}, 0.1f, {640, 480}), cv::Rect(0, 5, 120, 60));
  EXPECT_EQ(enlarge_box({600, 450, 100, 100}, 0.1f, {640, 480}), cv::Rect(590, 440, 50, 40));
}

}  // namespace
}  // namespace varslam::semantic
