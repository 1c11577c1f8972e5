#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.hpp"
#include "features/descriptor_matching.hpp"
#include "features/feature_extractor.hpp"
#include "features/orb_extractor.hpp"
#include "features/test_images.hpp"

namespace varslam {
namespace {

using testing::textured_image;

struct Extracted {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
};

Extracted extract(FeatureExtractor& ex, const cv::Mat& img) {
  Extracted e;
  ex.extract(img, e.keypoints, e.descriptors);
  return e;
}

// Share of the cells of a cols x rows grid over the image that hold at least one keypoint.
double grid_occupancy(const std::vector<cv::KeyPoint>& kps, cv::Size size, int cols = 16, int rows = 12) {
  std::vector<int> count(std::size_t(cols * rows), 0);
  for (const auto& k : kps) {
    const int c = std::clamp(int(k.pt.x * cols / size.width), 0, cols - 1);
    const int r = std::clamp(int(k.pt.y * rows / size.height), 0, rows - 1);
    ++count[std::size_t(r * cols + c)];
  }
  return double(std::count_if(count.begin(), count.end(), [](int n) { return n > 0; })) / double(count.size());
}

TEST(OrbExtractor, ScaleTablesFollowTheScaleFactor) {
  auto ex = make_extractor(OrbParams{});
  ASSERT_EQ(ex->n_levels(), 8);
  ASSERT_EQ(ex->scale_factors().size(), 8u);
  for (int l = 0; l < 8; ++l) {
    const double s = std::pow(1.2, l);
    EXPECT_NEAR(ex->scale_factors()[std::size_t(l)], s, 1e-12);
    EXPECT_NEAR(ex->level_sigma2()[std::size_t(l)], s * s, 1e-12);
    EXPECT_NEAR(ex->inv_level_sigma2()[std::size_t(l)], 1.0 / (s * s), 1e-12);
  }
}

TEST(OrbExtractor, LevelBudgetsAreAreaProportionalAndSumToTotal) {
  OrbExtractor ex(OrbParams{});
  const auto& b = ex.level_budgets();
  ASSERT_EQ(b.size(), 8u);
  int sum = 0;
  for (int v : b) sum += v;
  EXPECT_EQ(sum, 1000);
  for (std::size_t l = 1; l < b.size(); ++l) EXPECT_NEAR(double(b[l]) / b[l - 1], 1.0 / 1.44, 0.05);
}

TEST(OrbExtractor, RejectsBadParameters) {
  OrbParams p;
  p.scale_factor = 1.0;
  EXPECT_THROW(make_extractor(p), InputError);
  p = OrbParams{};
  p.min_th_fast = 30;
  EXPECT_THROW(make_extractor(p), InputError);
  p = OrbParams{};
  p.threads = 0;
  EXPECT_THROW(make_extractor(p), InputError);
}

TEST(OrbExtractor, ReturnsAboutTheBudgetInsideTheImage) {
  const cv::Mat img = textured_image(640, 480);
  auto ex = make_extractor(OrbParams{});
  const Extracted e = extract(*ex, img);
  EXPECT_GE(e.keypoints.size(), 950u);
  EXPECT_LE(e.keypoints.size(), 1000u);
  ASSERT_EQ(e.descriptors.rows, int(e.keypoints.size()));
  EXPECT_EQ(e.descriptors.cols, 32);
  EXPECT_EQ(e.descriptors.type(), CV_8UC1);
  std::vector<int> per_level(8, 0);
  for (const auto& k : e.keypoints) {
    EXPECT_GE(k.pt.x, 0.f);
    EXPECT_GE(k.pt.y, 0.f);
    EXPECT_LT(k.pt.x, 640.f);
    EXPECT_LT(k.pt.y, 480.f);
    ASSERT_GE(k.octave, 0);
    ASSERT_LT(k.octave, 8);
    EXPECT_GE(k.angle, 0.f);
    EXPECT_LT(k.angle, 360.f);
    EXPECT_NEAR(k.size, 31.0 * std::pow(1.2, k.octave), 1e-3);
    ++per_level[std::size_t(k.octave)];
  }
  for (int n : per_level) EXPECT_GT(n, 0);  // every level contributes
}

// The semantic filter masks people so the budget goes to the background: nothing inside the mask, and the
// allowed half gets about the whole budget (not just the half it would get unmasked).
TEST(OrbExtractor, MaskKeepsKeypointsOutAndSpendsTheBudgetElsewhere) {
  const cv::Mat img = textured_image(640, 480);
  cv::Mat1b mask(img.size(), uchar(255));
  mask(cv::Rect(0, 0, 320, 480)).setTo(0);
  for (ExtractorKind kind : {ExtractorKind::Ours, ExtractorKind::OpenCV}) {
    SCOPED_TRACE(kind == ExtractorKind::Ours ? "ours" : "opencv");
    auto ex = make_extractor(OrbParams{}, kind);
    Extracted whole = extract(*ex, img), masked;
    ex->extract(img, masked.keypoints, masked.descriptors, mask);
    const auto right = [](const std::vector<cv::KeyPoint>& kps) {
      return std::count_if(kps.begin(), kps.end(), [](const cv::KeyPoint& k) { return k.pt.x >= 320.f; });
    };
    EXPECT_EQ(right(masked.keypoints), static_cast<long>(masked.keypoints.size()));  // none on the masked half
    EXPECT_EQ(masked.descriptors.rows, static_cast<int>(masked.keypoints.size()));
    EXPECT_GE(masked.keypoints.size(), 0.9 * whole.keypoints.size());
    EXPECT_GT(right(masked.keypoints), 1.5 * right(whole.keypoints));
  }
}

TEST(OrbExtractor, MaskOfAnotherSizeIsRejected) {
  auto ex = make_extractor(OrbParams{});
  Extracted e;
  EXPECT_THROW(ex->extract(textured_image(640, 480), e.keypoints, e.descriptors, cv::Mat1b(240, 320, uchar(255))),
               std::invalid_argument);
}

TEST(OrbExtractor, LevelCoordinatesMapBackToTheSameImagePoint) {
  // A bright square on dark: its corners are found at several levels, all at the same level-0 position.
  cv::Mat img(480, 640, CV_8UC1, cv::Scalar(20));
  cv::rectangle(img, cv::Rect(200, 150, 240, 180), cv::Scalar(230), cv::FILLED);
  auto ex = make_extractor(OrbParams{});
  const Extracted e = extract(*ex, img);
  ASSERT_FALSE(e.keypoints.empty());
  const cv::Point2f corners[4] = {{200, 150}, {439, 150}, {200, 329}, {439, 329}};
  int near_corner = 0;
  for (const auto& k : e.keypoints) {
    float best = 1e9f;
    for (const auto& c : corners) best = std::min(best, float(cv::norm(k.pt - c)));
    // FAST centres sit about a pixel inside a corner; allow a pixel of slack per level step.
    if (best < 2.5f + 1.2f * float(k.octave)) ++near_corner;
  }
  EXPECT_GE(near_corner, int(e.keypoints.size() * 9 / 10));
  EXPECT_GT(std::count_if(e.keypoints.begin(), e.keypoints.end(), [](const cv::KeyPoint& k) { return k.octave >= 3; }),
            0);
}

TEST(OrbExtractor, SpreadsBetterThanTheStrongestCorners) {
  // Left half: full contrast; right half: weak but detectable texture. The N strongest corners all
  // crowd on the left; ours must still cover the right.
  cv::Mat img = textured_image(640, 480, 3, 1.0);
  textured_image(640, 480, 4, 0.18)(cv::Rect(320, 0, 320, 480)).copyTo(img(cv::Rect(320, 0, 320, 480)));
  auto ex = make_extractor(OrbParams{});
  const Extracted e = extract(*ex, img);
  ASSERT_GE(e.keypoints.size(), 900u);
  std::vector<cv::KeyPoint> level0, strongest;
  for (const auto& k : e.keypoints)
    if (k.octave == 0) level0.push_back(k);
  cv::FAST(img, strongest, 7, true);
  std::sort(strongest.begin(), strongest.end(),
            [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.response > b.response; });
  strongest.resize(std::min(strongest.size(), level0.size()));
  const double ours = grid_occupancy(level0, img.size());
  const double naive = grid_occupancy(strongest, img.size());
  EXPECT_GT(ours, naive + 0.2) << "ours " << ours << " strongest " << naive;
  const auto right = [](const std::vector<cv::KeyPoint>& v) {
    return std::count_if(v.begin(), v.end(), [](const cv::KeyPoint& k) { return k.pt.x > 330; });
  };
  EXPECT_GT(right(level0), long(level0.size()) / 4);
}

TEST(OrbExtractor, IsDeterministic) {
  const cv::Mat img = textured_image(640, 480, 11);
  auto a = make_extractor(OrbParams{});
  auto b = make_extractor(OrbParams{});
  const Extracted e1 = extract(*a, img);
  const Extracted e2 = extract(*a, img);  // same object again: reused buffers must not leak state
  const Extracted e3 = extract(*b, img);
  for (const Extracted* other : {&e2, &e3}) {
    ASSERT_EQ(other->keypoints.size(), e1.keypoints.size());
    for (std::size_t i = 0; i < e1.keypoints.size(); ++i) {
      EXPECT_EQ(other->keypoints[i].pt, e1.keypoints[i].pt);
      EXPECT_EQ(other->keypoints[i].angle, e1.keypoints[i].angle);
      EXPECT_EQ(other->keypoints[i].octave, e1.keypoints[i].octave);
    }
    EXPECT_EQ(cv::norm(other->descriptors, e1.descriptors, cv::NORM_HAMMING), 0.0);
  }
}

TEST(OrbExtractor, ThreadCountDoesNotChangeTheKeypoints) {
  // Levels run side by side; the budgets pass from level to level, so a level's share must not depend on
  // which level finished first. A mask and a small budget make the carry between levels matter.
  const cv::Mat img = textured_image(640, 480, 5);
  cv::Mat1b mask(img.size(), uchar(255));
  mask(cv::Rect(100, 0, 300, 480)).setTo(0);
  for (const int n_features : {1000, 150}) {
    for (const bool masked : {false, true}) {
      SCOPED_TRACE(std::to_string(n_features) + (masked ? " masked" : ""));
      OrbParams one;
      one.n_features = n_features;
      one.threads = 1;
      auto reference = make_extractor(one);
      Extracted ref;
      reference->extract(img, ref.keypoints, ref.descriptors, masked ? cv::Mat(mask) : cv::Mat());
      ASSERT_GT(ref.keypoints.size(), 0.8 * n_features);
      for (const int threads : {2, 3, 8}) {
        OrbParams p = one;
        p.threads = threads;
        auto ex = make_extractor(p);
        for (int repeat = 0; repeat < 3; ++repeat) {
          Extracted e;
          ex->extract(img, e.keypoints, e.descriptors, masked ? cv::Mat(mask) : cv::Mat());
          ASSERT_EQ(e.keypoints.size(), ref.keypoints.size()) << threads << " threads";
          for (std::size_t i = 0; i < e.keypoints.size(); ++i) {
            ASSERT_EQ(e.keypoints[i].pt, ref.keypoints[i].pt) << i;
            ASSERT_EQ(e.keypoints[i].angle, ref.keypoints[i].angle) << i;
            ASSERT_EQ(e.keypoints[i].octave, ref.keypoints[i].octave) << i;
            ASSERT_EQ(e.keypoints[i].response, ref.keypoints[i].response) << i;
          }
          ASSERT_EQ(cv::norm(e.descriptors, ref.descriptors, cv::NORM_HAMMING), 0.0);
        }
      }
    }
  }
}

TEST(OrbExtractor, ConstantImageGivesNoKeypoints) {
  for (ExtractorKind kind : {ExtractorKind::Ours, ExtractorKind::OpenCV}) {
    auto ex = make_extractor(OrbParams{}, kind);
    const Extracted e = extract(*ex, cv::Mat(480, 640, CV_8UC1, cv::Scalar(77)));
    EXPECT_TRUE(e.keypoints.empty());
    EXPECT_EQ(e.descriptors.rows, 0);
  }
}

TEST(OrbExtractor, TinyAndEmptyImagesDoNotCrash) {
  for (ExtractorKind kind : {ExtractorKind::Ours, ExtractorKind::OpenCV}) {
    auto ex = make_extractor(OrbParams{}, kind);
    for (const cv::Size size : {cv::Size(0, 0), cv::Size(1, 1), cv::Size(5, 3), cv::Size(33, 33), cv::Size(40, 64)}) {
      const cv::Mat img = size.area() > 0 ? textured_image(size.width, size.height) : cv::Mat();
      Extracted e;
      ASSERT_NO_THROW(ex->extract(img, e.keypoints, e.descriptors)) << size;
      EXPECT_EQ(e.descriptors.rows, int(e.keypoints.size()));
      for (const auto& k : e.keypoints) {
        EXPECT_GE(k.pt.x, 0.f);
        EXPECT_LT(k.pt.x, float(size.width));
      }
    }
  }
}

TEST(OrbExtractor, AcceptsColourImages) {
  const cv::Mat gray = textured_image(320, 240);
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  auto ex = make_extractor(OrbParams{});
  const Extracted a = extract(*ex, gray), b = extract(*ex, bgr);
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
  EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_HAMMING), 0.0);
}

TEST(OrbExtractor, OpenCvWrapperHonoursTheParameters) {
  OrbParams p;
  p.n_features = 500;
  p.n_levels = 4;
  auto ex = make_extractor(p, ExtractorKind::OpenCV);
  const Extracted e = extract(*ex, textured_image(640, 480));
  EXPECT_GT(e.keypoints.size(), 400u);
  EXPECT_LE(e.keypoints.size(), 500u);
  EXPECT_EQ(e.descriptors.rows, int(e.keypoints.size()));
  for (const auto& k : e.keypoints) EXPECT_LT(k.octave, 4);
}

// Rotates `img` by `deg` about its centre; returns the 2x3 map from original to rotated pixels.
cv::Mat rotate_image(const cv::Mat& img, double deg, cv::Mat& rotated) {
  const cv::Point2f centre((img.cols - 1) * 0.5f, (img.rows - 1) * 0.5f);
  const cv::Mat M = cv::getRotationMatrix2D(centre, deg, 1.0);
  cv::warpAffine(img, rotated, M, img.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(128));
  return M;
}

struct InvarianceResult {
  int compared = 0;     // keypoints of the original re-detected at their rotated position
  int angle_ok = 0;     // ... whose angle moved by the rotation
  int descriptor_ok = 0;  // ... whose descriptors still match
};

InvarianceResult check_rotation(double deg) {
  // A disc-shaped textured region, so rotating it loses nothing near the middle.
  const cv::Mat img = textured_image(640, 480, 21);
  cv::Mat rotated;
  const cv::Mat M = rotate_image(img, deg, rotated);
  auto ex = make_extractor(OrbParams{});
  const Extracted a = extract(*ex, img), b = extract(*ex, rotated);
  const cv::Matx22d R(M.at<double>(0, 0), M.at<double>(0, 1), M.at<double>(1, 0), M.at<double>(1, 1));
  InvarianceResult res;
  for (int i = 0; i < int(a.keypoints.size()); ++i) {
    const cv::KeyPoint& ka = a.keypoints[std::size_t(i)];
    if (cv::norm(ka.pt - cv::Point2f(320, 240)) > 170) continue;  // keep clear of the rotated-in border
    const cv::Point2f p(float(R(0, 0) * ka.pt.x + R(0, 1) * ka.pt.y + M.at<double>(0, 2)),
                        float(R(1, 0) * ka.pt.x + R(1, 1) * ka.pt.y + M.at<double>(1, 2)));
    int match = -1;
    float best = 1.5f * float(std::pow(1.2, ka.octave));
    for (int j = 0; j < int(b.keypoints.size()); ++j) {
      const cv::KeyPoint& kb = b.keypoints[std::size_t(j)];
      if (kb.octave != ka.octave) continue;
      const float d = float(cv::norm(kb.pt - p));
      if (d < best) best = d, match = j;
    }
    if (match < 0) continue;
    ++res.compared;
    // Expected angle: the keypoint's direction vector carried through the rotation.
    const double ra = ka.angle * CV_PI / 180.0;
    const cv::Vec2d dir = R * cv::Vec2d(std::cos(ra), std::sin(ra));
    const double expected = std::atan2(dir[1], dir[0]) * 180.0 / CV_PI;
    double diff = std::fmod(std::abs(b.keypoints[std::size_t(match)].angle - expected), 360.0);
    diff = std::min(diff, 360.0 - diff);
    if (diff < 15.0) ++res.angle_ok;
    if (descriptor_distance(a.descriptors.row(i), b.descriptors.row(match)) < 64) ++res.descriptor_ok;
  }
  return res;
}

TEST(OrbExtractor, OrientationFollowsA90DegreeRotation) {
  const InvarianceResult r = check_rotation(90.0);
  ASSERT_GE(r.compared, 100);
  EXPECT_GE(r.angle_ok, r.compared * 85 / 100) << r.angle_ok << "/" << r.compared;
  EXPECT_GE(r.descriptor_ok, r.compared * 80 / 100) << r.descriptor_ok << "/" << r.compared;
}

TEST(OrbExtractor, OrientationFollowsA30DegreeRotation) {
  const InvarianceResult r = check_rotation(30.0);
  ASSERT_GE(r.compared, 100);
  EXPECT_GE(r.angle_ok, r.compared * 75 / 100) << r.angle_ok << "/" << r.compared;
  EXPECT_GE(r.descriptor_ok, r.compared * 65 / 100) << r.descriptor_ok << "/" << r.compared;
}

}  // namespace
}  // namespace varslam
