#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <tuple>

#include "features/fast_grid.hpp"
#include "features/keypoint_spread.hpp"
#include "features/orb_descriptor.hpp"

namespace varslam {
namespace {

TEST(FastGrid, FallsBackToTheLowThresholdOnlyWhereNeeded) {
  // Left: strong squares (contrast 100); right: faint squares (contrast 12, between the two thresholds).
  cv::Mat img(240, 320, CV_8UC1, cv::Scalar(100));
  for (int y = 20; y < 220; y += 30)
    for (int x = 20; x < 300; x += 30)
      cv::rectangle(img, cv::Rect(x, y, 10, 10), cv::Scalar(x < 160 ? 200 : 112), cv::FILLED);
  // Perfect squares give exactly tied FAST scores that suppress each other; a little noise breaks the ties
  // (too little to make corners on flat grey at threshold 7).
  cv::Mat noise(img.size(), CV_8UC1);
  cv::RNG(1).fill(noise, cv::RNG::UNIFORM, 0, 3);
  img += noise;
  const cv::Rect region(16, 16, 288, 208);
  std::vector<cv::KeyPoint> high_only, with_fallback;
  detect_fast_grid(img, region, {30, 20, 20}, high_only);
  detect_fast_grid(img, region, {30, 20, 7}, with_fallback);
  const auto on_right = [](const std::vector<cv::KeyPoint>& v) {
    return std::count_if(v.begin(), v.end(), [](const cv::KeyPoint& k) { return k.pt.x >= 165; });
  };
  EXPECT_EQ(on_right(high_only), 0);
  EXPECT_GT(on_right(with_fallback), 20);
  // The strong half is not searched again: it keeps exactly its high-threshold corners.
  EXPECT_EQ(with_fallback.size() - std::size_t(on_right(with_fallback)), high_only.size());
  for (const auto& k : with_fallback) EXPECT_TRUE(region.contains(cv::Point(int(k.pt.x), int(k.pt.y))));
}

// The fallback as first written: one cv::FAST call per empty cell, on the cell grown by FAST's radius.
std::vector<cv::KeyPoint> reference_fast_grid(const cv::Mat& image, const cv::Rect& region, const FastGridParams& p) {
  const int cols = std::max(1, static_cast<int>(std::lround(region.width / double(p.cell_size))));
  const int rows = std::max(1, static_cast<int>(std::lround(region.height / double(p.cell_size))));
  std::vector<int> xs, ys;
  for (int c = 0; c <= cols; ++c) xs.push_back(region.x + c * region.width / cols);
  for (int r = 0; r <= rows; ++r) ys.push_back(region.y + r * region.height / rows);
  const auto search = [&](const cv::Rect& rect, int threshold, std::vector<cv::KeyPoint>& out) {
    std::vector<cv::KeyPoint> found;
    const cv::Rect grown(rect.x - 3, rect.y - 3, rect.width + 6, rect.height + 6);
    cv::FAST(image(grown), found, threshold, true);
    for (cv::KeyPoint k : found) {
      k.pt += cv::Point2f(float(grown.x), float(grown.y));
      if (rect.contains(cv::Point(int(k.pt.x), int(k.pt.y)))) out.push_back(k);
    }
  };
  std::vector<cv::KeyPoint> corners;
  search(region, p.ini_threshold, corners);
  std::vector<bool> occupied(std::size_t(cols * rows), false);
  for (const auto& k : corners) {
    const int c = int(std::upper_bound(xs.begin() + 1, xs.end() - 1, int(k.pt.x)) - xs.begin()) - 1;
    const int r = int(std::upper_bound(ys.begin() + 1, ys.end() - 1, int(k.pt.y)) - ys.begin()) - 1;
    occupied[std::size_t(r * cols + c)] = true;
  }
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      if (!occupied[std::size_t(r * cols + c)])
        search(cv::Rect(xs[std::size_t(c)], ys[std::size_t(r)], xs[std::size_t(c) + 1] - xs[std::size_t(c)],
                        ys[std::size_t(r) + 1] - ys[std::size_t(r)]),
               p.min_threshold, corners);
  return corners;
}

TEST(FastGrid, EmptyCellsSearchedTogetherGiveTheCornersOfOneSearchPerCell) {
  // Faint texture (between the two thresholds) over most of the image, strong blobs in a few places: long runs
  // of empty cells side by side, corners on the borders between them, and plateaus of tied scores.
  cv::RNG rng(5);
  cv::Mat noise(240, 320, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 92, 112);  // differences up to 19: under the first threshold
  cv::Mat img = noise;
  for (int i = 0; i < 6; ++i) cv::circle(img, cv::Point(rng.uniform(20, 300), rng.uniform(20, 220)), 5, cv::Scalar(220), cv::FILLED);
  cv::rectangle(img, cv::Rect(100, 150, 90, 8), cv::Scalar(140), cv::FILLED);
  for (const FastGridParams p : {FastGridParams{30, 20, 7}, FastGridParams{30, 20, 3}, FastGridParams{17, 40, 10}}) {
    const cv::Rect region(16, 16, 288, 208);
    std::vector<cv::KeyPoint> got;
    detect_fast_grid(img, region, p, got);
    const auto expected = reference_fast_grid(img, region, p);
    ASSERT_EQ(got.size(), expected.size()) << "cell " << p.cell_size << ", thresholds " << p.min_threshold;
    ASSERT_GT(got.size(), 100u) << "the faint texture gives the fallback work";
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].pt, expected[i].pt) << i;
      EXPECT_EQ(got[i].response, expected[i].response) << i;
      EXPECT_EQ(got[i].size, expected[i].size) << i;
    }
  }
}

TEST(SpreadKeypoints, RoundRobinOverCellsBeforeSecondBest) {
  // 50 strong corners crowded in one corner, 10 weak ones scattered: a budget of 20 takes all 10 weak ones.
  std::vector<cv::KeyPoint> c;
  // Cells are ~95 px here: the weak corners each sit in a cell of their own, away from the cluster's.
  for (int i = 0; i < 50; ++i)
    c.emplace_back(cv::Point2f(300.f + float(i % 7), 140.f + float(i / 7)), 7.f, -1.f, 100.f + float(i));
  for (int i = 0; i < 10; ++i)
    c.emplace_back(cv::Point2f(50.f + 110.f * float(i % 5), 60.f + 150.f * float(i / 5)), 7.f, -1.f, 10.f);
  const cv::Rect region(0, 0, 600, 300);
  const auto kept = spread_keypoints(c, region, 20);
  ASSERT_EQ(kept.size(), 20u);
  EXPECT_EQ(std::count_if(kept.begin(), kept.end(), [](const cv::KeyPoint& k) { return k.response == 10.f; }), 10);
  // The crowded cluster contributes its strongest corner first.
  EXPECT_TRUE(std::any_of(kept.begin(), kept.end(), [](const cv::KeyPoint& k) { return k.response == 149.f; }));
  EXPECT_EQ(spread_keypoints(c, region, 100).size(), c.size());
  EXPECT_TRUE(spread_keypoints(c, region, 0).empty());
}

TEST(SpreadKeypoints, IsIndependentOfCandidateOrder) {
  std::vector<cv::KeyPoint> c;
  cv::RNG rng(5);
  for (int i = 0; i < 500; ++i)
    c.emplace_back(cv::Point2f(float(rng.uniform(0, 300)), float(rng.uniform(0, 200))), 7.f, -1.f,
                   float(rng.uniform(7, 40)));
  auto reversed = c;
  std::reverse(reversed.begin(), reversed.end());
  const auto key = [](const cv::KeyPoint& k) { return std::make_tuple(k.pt.x, k.pt.y, k.response); };
  std::set<std::tuple<float, float, float>> a, b;
  for (const auto& k : spread_keypoints(c, cv::Rect(0, 0, 300, 200), 60)) a.insert(key(k));
  for (const auto& k : spread_keypoints(reversed, cv::Rect(0, 0, 300, 200), 60)) b.insert(key(k));
  EXPECT_EQ(a, b);
}

TEST(BriefPattern, IsFixedInsideThePatchAndWithoutRepeats) {
  const auto& p = brief_pattern();
  std::set<std::tuple<int, int, int, int>> seen;
  int max_abs = 0;
  double sum_r2 = 0;
  for (const BriefPair& q : p) {
    EXPECT_LE(q.x1 * q.x1 + q.y1 * q.y1, kOrbPatchRadius * kOrbPatchRadius);
    EXPECT_LE(q.x2 * q.x2 + q.y2 * q.y2, kOrbPatchRadius * kOrbPatchRadius);
    EXPECT_FALSE(q.x1 == q.x2 && q.y1 == q.y2);
    EXPECT_TRUE(seen.insert({q.x1, q.y1, q.x2, q.y2}).second);
    max_abs = std::max({max_abs, std::abs(int(q.x1)), std::abs(int(q.y2))});
    sum_r2 += q.x1 * q.x1 + q.y1 * q.y1 + q.x2 * q.x2 + q.y2 * q.y2;
  }
  // Gaussian with sigma 6.2 truncated at radius 15: mean squared radius a bit under 2 sigma^2 = 77.
  const double mean_r2 = sum_r2 / 512.0;
  EXPECT_GT(mean_r2, 50.0);
  EXPECT_LT(mean_r2, 80.0);
  EXPECT_GE(max_abs, 12);
  EXPECT_EQ(&brief_pattern(), &p);
}

TEST(CentroidOrientation, PointsTowardsTheBrightSide) {
  cv::Mat img(64, 64, CV_8UC1, cv::Scalar(0));
  img(cv::Rect(32, 0, 32, 64)).setTo(200);  // bright to the right (+x): angle 0
  CentroidOrientation o;
  EXPECT_NEAR(o.angle_deg(img, 32, 32), 0.0, 3.0);
  cv::Mat down(64, 64, CV_8UC1, cv::Scalar(0));
  down(cv::Rect(0, 32, 64, 32)).setTo(200);  // bright below (+y, image axes): angle 90
  EXPECT_NEAR(o.angle_deg(down, 32, 32), 90.0, 3.0);
  cv::Mat up_left(64, 64, CV_8UC1, cv::Scalar(0));
  up_left(cv::Rect(0, 0, 32, 32)).setTo(200);  // bright up-left: angle 225
  EXPECT_NEAR(o.angle_deg(up_left, 32, 32), 225.0, 3.0);
}

}  // namespace
}  // namespace varslam
