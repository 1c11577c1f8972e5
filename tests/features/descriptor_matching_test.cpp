#include <gtest/gtest.h>

#include <algorithm>
#include <bitset>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "features/descriptor_matching.hpp"
#include "features/feature_extractor.hpp"
#include "features/test_images.hpp"

namespace varslam {
namespace {

cv::Mat random_descriptors(int n, std::uint64_t seed) {
  cv::Mat d(n, 32, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(d, cv::RNG::UNIFORM, 0, 256);
  return d;
}

int reference_distance(const std::uint8_t* a, const std::uint8_t* b) {
  int d = 0;
  for (int i = 0; i < 32; ++i) d += int(std::bitset<8>(unsigned(a[i] ^ b[i])).count());
  return d;
}

// Copy of `d` with `bits` distinct bits flipped (chosen by `seed`).
cv::Mat flip_bits(const cv::Mat& d, int bits, std::uint64_t seed) {
  cv::Mat out = d.clone();
  cv::RNG rng(seed);
  std::vector<int> idx(256);
  for (int i = 0; i < 256; ++i) idx[std::size_t(i)] = i;
  for (int i = 0; i < bits; ++i) std::swap(idx[std::size_t(i)], idx[std::size_t(rng.uniform(i, 256))]);
  for (int i = 0; i < bits; ++i) out.data[idx[std::size_t(i)] / 8] ^= std::uint8_t(1u << (idx[std::size_t(i)] % 8));
  return out;
}

TEST(DescriptorDistance, AgreesWithBitCountReference) {
  const cv::Mat a = random_descriptors(50, 1), b = random_descriptors(50, 2);
  for (int i = 0; i < 50; ++i) {
    const int ref = reference_distance(a.ptr(i), b.ptr(i));
    EXPECT_EQ(descriptor_distance(a.ptr(i), b.ptr(i)), ref);
    EXPECT_EQ(descriptor_distance(a.row(i), b.row(i)), ref);
  }
  EXPECT_EQ(descriptor_distance(a.row(3), a.row(3)), 0);
  cv::Mat zeros(1, 32, CV_8UC1, cv::Scalar(0)), ones(1, 32, CV_8UC1, cv::Scalar(255));
  EXPECT_EQ(descriptor_distance(zeros, ones), 256);
  EXPECT_EQ(descriptor_distance(zeros, flip_bits(zeros, 17, 5)), 17);
}

TEST(DescriptorDistance, WorksOnUnalignedRows) {
  const cv::Mat big = random_descriptors(1, 9).reshape(1, 1);
  std::vector<std::uint8_t> buf(40);
  std::copy(big.data, big.data + 32, buf.begin() + 3);  // deliberately misaligned copy
  const cv::Mat other = random_descriptors(1, 10);
  EXPECT_EQ(descriptor_distance(buf.data() + 3, other.data), reference_distance(big.data, other.data));
}

TEST(DescriptorDistance, RejectsWrongShapes) {
  EXPECT_THROW(descriptor_distance(cv::Mat(1, 16, CV_8UC1), cv::Mat(1, 16, CV_8UC1)), std::invalid_argument);
  EXPECT_THROW(descriptor_distance(cv::Mat(2, 32, CV_8UC1), cv::Mat(1, 32, CV_8UC1)), std::invalid_argument);
}

TEST(MatchDescriptors, FindsNoisyCopiesAndRejectsTheAmbiguous) {
  const cv::Mat train = random_descriptors(200, 3);
  // Query i is train row (i * 7) % 200 with 20 bits flipped; row 0 of query is garbage.
  cv::Mat query(100, 32, CV_8UC1);
  for (int i = 0; i < 100; ++i) flip_bits(train.row((i * 7) % 200), 20, 100 + std::uint64_t(i)).copyTo(query.row(i));
  random_descriptors(1, 77).copyTo(query.row(0));
  const auto m = match_descriptors(query, train, 60, 0.8, true);
  ASSERT_EQ(m.size(), 99u);  // random 256-bit strings are ~128 bits apart: row 0 finds nothing within 60
  for (const auto& x : m) {
    EXPECT_EQ(x.train, (x.query * 7) % 200);
    EXPECT_EQ(x.distance, 20);
  }
  // Two identical train rows: the ratio test must refuse to choose.
  cv::Mat twins;
  cv::vconcat(train.row(5), train.row(5), twins);
  EXPECT_TRUE(match_descriptors(train.row(5), twins, 60, 0.8, false).empty());
  EXPECT_EQ(match_descriptors(train.row(5), twins, 60, 1.0, false).size(), 1u);  // ratio 1 disables the test
  EXPECT_TRUE(match_descriptors(query.row(1), train, 19, 0.8, false).empty());    // max distance honoured
}

TEST(MatchDescriptors, UniqueKeepsTheBestQueryPerTrainRow) {
  const cv::Mat train = random_descriptors(10, 4);
  cv::Mat query;
  cv::vconcat(std::vector<cv::Mat>{flip_bits(train.row(2), 30, 1), flip_bits(train.row(2), 10, 2),
                                   flip_bits(train.row(6), 5, 3)},
              query);
  const auto all = match_descriptors(query, train, 64, 0.9, false);
  EXPECT_EQ(all.size(), 3u);
  const auto uniq = match_descriptors(query, train, 64, 0.9, true);
  ASSERT_EQ(uniq.size(), 2u);
  EXPECT_EQ(uniq[0].query, 1);
  EXPECT_EQ(uniq[0].train, 2);
  EXPECT_EQ(uniq[1].query, 2);
  EXPECT_EQ(uniq[1].train, 6);
}

TEST(MatchDescriptors, MatchesAnImageWithItsShiftedCopy) {
  const cv::Mat img = testing::textured_image(640, 480, 31);
  const int dx = 17, dy = -9;
  cv::Mat shifted;
  const cv::Mat T = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::warpAffine(img, shifted, T, img.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(128));
  auto ex = make_extractor(OrbParams{});
  std::vector<cv::KeyPoint> ka, kb;
  cv::Mat da, db;
  ex->extract(img, ka, da);
  ex->extract(shifted, kb, db);
  const auto m = match_descriptors(da, db, 50, 0.8, true);
  ASSERT_GE(m.size(), 300u);
  int right = 0;
  for (const auto& x : m) {
    const cv::Point2f expected = ka[std::size_t(x.query)].pt + cv::Point2f(dx, dy);
    if (cv::norm(kb[std::size_t(x.train)].pt - expected) < 1.5 * std::pow(1.2, ka[std::size_t(x.query)].octave))
      ++right;
  }
  EXPECT_GE(right, int(m.size() * 95 / 100)) << right << " of " << m.size();
}

TEST(RotationConsistent, KeepsTheThreeFullestBins) {
  // 10 at ~5 deg (bin 0), 6 at ~100 (bin 8), 4 at ~-10 = 350 (bin 29), 2 at ~200 (bin 16), 1 at 725 = 5 (bin 0).
  std::vector<float> d;
  for (int i = 0; i < 10; ++i) d.push_back(5.f + 0.3f * float(i));
  for (int i = 0; i < 6; ++i) d.push_back(100.f);
  for (int i = 0; i < 4; ++i) d.push_back(-10.f);
  d.push_back(200.f);
  d.push_back(201.f);
  d.push_back(725.f);
  const std::vector<int> kept = rotation_consistent(d);
  std::vector<int> expected;
  for (int i = 0; i < 20; ++i) expected.push_back(i);
  expected.push_back(22);
  EXPECT_EQ(kept, expected);
  EXPECT_TRUE(rotation_consistent({}).empty());
  EXPECT_EQ(rotation_consistent({42.f}), std::vector<int>{0});
}

TEST(MedoidDescriptor, PicksTheMostCentralDescriptor) {
  const cv::Mat base = random_descriptors(1, 12);
  // Four noisy copies of `base` (8 bits each, base itself is not in the set), one far outlier, and the
  // exact centre at index 3: it has the least median distance.
  std::vector<cv::Mat> set = {flip_bits(base, 8, 1), flip_bits(base, 8, 2), random_descriptors(1, 99), base.clone(),
                              flip_bits(base, 8, 3), flip_bits(base, 8, 4)};
  EXPECT_EQ(medoid_descriptor(set), 3);
  EXPECT_EQ(medoid_descriptor({}), -1);
  EXPECT_EQ(medoid_descriptor({base}), 0);
}

}  // namespace
}  // namespace varslam
