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

// The extraction mask is the filter's rule per pixel: a keypoint at an allowed pixel is one the filter keeps.
TEST(KeypointFilter, AllowedPixelsAreWhereTheFilterKeeps) {
  const Scene scene;
  const cv::Mat allowed = allowed_pixels(scene.depth.size(), scene.depth, scene.boxes(), FilterConfig{});
  ASSERT_EQ(allowed.type(), CV_8UC1);
  ASSERT_EQ(allowed.size(), scene.depth.size());
  std::vector<cv::KeyPoint> kps;
  for (int y = 4; y < 480; y += 8)
    for (int x = 4; x < 640; x += 8) kps.push_back(kp(static_cast<float>(x), static_cast<float>(y)));
  const auto keep = filter_keypoints(kps, scene.depth, scene.boxes(), FilterConfig{});
  int masked = 0;
  for (std::size_t i = 0; i < kps.size(); ++i) {
    const bool ok = allowed.at<uchar>(cv::Point(kps[i].pt)) != 0;
    masked += !ok;
    EXPECT_EQ(ok, static_cast<bool>(keep[i])) << "at " << kps[i].pt;
  }
  EXPECT_GT(masked, 200);  // the person and the hole
  EXPECT_TRUE(allowed_pixels(scene.depth.size(), scene.depth, Detections{}, FilterConfig{}).empty());  // no boxes: no mask
  // Without depth the whole enlarged box is masked, as the filter drops every keypoint in it.
  const cv::Mat no_depth = allowed_pixels(scene.depth.size(), cv::Mat(), scene.boxes(), FilterConfig{});
  EXPECT_EQ(no_depth.at<uchar>(240, 230), 0);
  EXPECT_EQ(no_depth.at<uchar>(240, 100), 255);
}

// The masker locates the people once per frame and hands the result to both the mask and the filter: that must
// decide exactly as the per-call functions do, also for a box reaching past the image border and without depth.
TEST(KeypointFilter, PeopleLocatedOnceDecideAsTheBoxesDo) {
  const Scene scene;
  Detections boxes = scene.boxes();
  Detection edge;
  edge.label = "person";
  edge.box = cv::Rect2f(560, 300, 120, 220);  // past the right and bottom borders
  boxes.push_back(edge);
  std::vector<cv::KeyPoint> kps;
  for (int y = 3; y < 480; y += 6)
    for (int x = 3; x < 640; x += 6) kps.push_back(kp(static_cast<float>(x), static_cast<float>(y)));
  const FilterConfig cfg;
  for (const cv::Mat& depth : {scene.depth, cv::Mat()}) {
    const PersonRegions people = locate_people(scene.depth.size(), depth, boxes, cfg);
    ASSERT_EQ(people.rects.size(), 2u);
    EXPECT_EQ(people.has_depth, !depth.empty());
    FilterStats once, per_call;
    EXPECT_EQ(filter_keypoints(kps, depth, people, cfg, &once), filter_keypoints(kps, depth, boxes, cfg, &per_call));
    EXPECT_EQ(once.dropped, per_call.dropped);
    EXPECT_GT(once.dropped, 100);
    const cv::Mat a = allowed_pixels(scene.depth.size(), depth, people, cfg);
    const cv::Mat b = allowed_pixels(scene.depth.size(), depth, boxes, cfg);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(cv::countNonZero(a != b), 0);
  }
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
  const auto keep = filter_keypoints({kp(320, 200), kp(1, 1)}, scene.depth, Detections{}, FilterConfig{}, &stats);
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

// Two people: a near one (1.2 m) whose box overlaps the left part of a farther one's box (2.3 m); wall at 4 m.
struct TwoPeople {
  cv::Mat depth{480, 640, CV_32FC1, cv::Scalar(4.0f)};
  cv::Rect near_person{150, 60, 180, 400}, far_person{300, 150, 90, 250};
  TwoPeople() {
    depth(far_person).setTo(2.3f);
    depth(near_person).setTo(1.2f);  // drawn last: it occludes the far person's left part
  }
  static Detection box(const cv::Rect& r) {
    Detection d;
    d.label = "person";
    d.box = cv::Rect2f(r);
    return d;
  }
  Detections boxes() const { return {box(near_person), box(far_person)}; }
};

FilterConfig exact_boxes(float share) {
  FilterConfig cfg;
  cfg.box_enlarge = 0.0f;
  cfg.min_exclusive_share = share;
  return cfg;
}

TEST(KeypointFilter, OverlappingNearerPersonCapturesTheWholeBoxEstimateButNotTheOwnPartOne) {
  const TwoPeople s;
  const std::vector<cv::Rect> rects = {s.near_person, s.far_person};
  const auto on = estimate_person_depths(s.depth, rects, exact_boxes(0.2f));
  ASSERT_EQ(on.size(), 2u);
  EXPECT_NEAR(on[0].whole_m, 1.2f, 0.06f);
  EXPECT_EQ(on[0].own_part_m, 0.0f);          // its own part says the same: no second depth
  EXPECT_NEAR(on[1].whole_m, 1.2f, 0.06f);    // the near person's part is the nearest strong mode
  EXPECT_NEAR(on[1].own_part_m, 2.3f, 0.06f);  // the part only this box covers finds the far person
  const auto off = estimate_person_depths(s.depth, rects, exact_boxes(1.0f));
  EXPECT_EQ(off[1].own_part_m, 0.0f);
  EXPECT_NEAR(off[1].whole_m, 1.2f, 0.06f);
}

TEST(KeypointFilter, FarPersonBehindAnOverlappingNearOneIsDroppedWithTheOwnPartDepth) {
  const TwoPeople s;
  const std::vector<cv::KeyPoint> kps = {kp(360, 250), kp(200, 250), kp(500, 250)};  // far person, near, wall outside
  const auto off = filter_keypoints(kps, s.depth, s.boxes(), exact_boxes(1.0f));
  EXPECT_EQ(off, (std::vector<bool>{true, false, true}));  // the leak: far person counted as background
  const auto on = filter_keypoints(kps, s.depth, s.boxes(), exact_boxes(0.2f));
  EXPECT_EQ(on, (std::vector<bool>{false, false, true}));
}

TEST(KeypointFilter, OwnPartEstimateNeedsEnoughOfTheBoxLeft) {
  TwoPeople s;
  s.far_person = cv::Rect(160, 100, 200, 250);  // almost all of it inside the near person's box
  s.depth = cv::Mat(480, 640, CV_32FC1, cv::Scalar(4.0f));
  s.depth(s.far_person).setTo(2.3f);
  s.depth(s.near_person).setTo(1.2f);
  const auto d = estimate_person_depths(s.depth, {s.near_person, s.far_person}, exact_boxes(0.2f));
  EXPECT_EQ(d[1].own_part_m, 0.0f);  // 30 of 200 columns left: below 20 % of the samples
}

// Person at 1.5 m filling x in [300, 340) of its box, wall at 4 m around it.
struct Silhouette {
  cv::Mat depth{480, 640, CV_32FC1, cv::Scalar(4.0f)};
  Silhouette() { depth(cv::Rect(300, 100, 40, 300)).setTo(1.5f); }
  Detections boxes() const {
    Detection d;
    d.label = "person";
    d.box = cv::Rect2f(260, 80, 120, 340);
    return {d};
  }
};

TEST(KeypointFilter, SilhouetteMarginDropsWallKeypointsNextToThePersonOnly) {
  const Silhouette s;
  // Wall 3 px left of the person, wall 20 px left, person; a coarse keypoint (size 62 = level with scale 2) 8 px off.
  const std::vector<cv::KeyPoint> kps = {kp(296, 200), kp(279, 200), kp(320, 200), cv::KeyPoint(348, 250, 62.f)};
  FilterConfig cfg;
  cfg.silhouette_margin_px = 0.0f;
  EXPECT_EQ(filter_keypoints(kps, s.depth, s.boxes(), cfg), (std::vector<bool>{true, true, false, true}));
  cfg.silhouette_margin_px = 5.0f;
  FilterStats stats;
  EXPECT_EQ(filter_keypoints(kps, s.depth, s.boxes(), cfg, &stats), (std::vector<bool>{false, true, false, false}));
  EXPECT_EQ(stats.dropped, 3);
  EXPECT_EQ(stats.dropped_silhouette, 2);
  EXPECT_EQ(stats.kept_background, 1);
}

TEST(KeypointFilter, DistanceToPersonIsZeroOnThePersonAndGrowsAway) {
  const Silhouette s;
  PersonDepth p;
  p.whole_m = 1.5f;
  const cv::Rect roi(260, 80, 120, 340);
  const cv::Mat dist = distance_to_person(s.depth, roi, p, FilterConfig{});
  ASSERT_EQ(dist.size(), roi.size());
  EXPECT_EQ(dist.at<float>(120, 60), 0.0f);               // (320, 200): on the person
  EXPECT_NEAR(dist.at<float>(120, 36), 4.0f, 0.5f);       // (296, 200): 4 px left of x = 300
  EXPECT_GT(dist.at<float>(120, 5), 20.0f);               // (265, 200)
}

}  // namespace
}  // namespace varslam::semantic
