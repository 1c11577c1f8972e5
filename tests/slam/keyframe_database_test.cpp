// Place recognition: signatures keep the strongest keypoints, queries rank keyframes of the same scene first and
// honour min_score, exclusion, bad keyframes and the candidate cap.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "slam/keyframe_database.hpp"
#include "slam/synthetic_map.hpp"

namespace varslam::slam {
namespace {

using synthetic::Keypoint;

bool same_row(const cv::Mat& a, int ra, const cv::Mat& b, int rb) {
  return std::equal(a.ptr<std::uint8_t>(ra), a.ptr<std::uint8_t>(ra) + kDescriptorBytes, b.ptr<std::uint8_t>(rb));
}

KeyFramePtr keyframe_of(long id, std::shared_ptr<const FrameFeatures> f) {
  return std::make_shared<KeyFrame>(id, Frame(id, static_cast<double>(id), std::move(f)));
}

/// A scene of strong keypoints (responses 0.5-1) that every view of it shares.
struct Scene {
  cv::Mat descriptors;
  std::vector<float> responses;
};

Scene make_scene(int n, std::mt19937& rng) {
  std::uniform_real_distribution<float> strong(0.5f, 1.0f);
  Scene s{synthetic::random_descriptors(n, rng), {}};
  for (int i = 0; i < n; ++i) s.responses.push_back(strong(rng));
  return s;
}

/// One view of the scene: each scene descriptor with up to 6 flipped bits (a fraction `replaced` swapped for
/// random ones: parts of the scene not seen), responses jittered, interleaved with as many weak clutter keypoints
/// (responses below 0.5, random descriptors) so that only the strongest keypoints make a useful signature.
std::shared_ptr<FrameFeatures> view_of(const Scene& s, double replaced, std::mt19937& rng) {
  const int n = s.descriptors.rows;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<float> jitter(-0.005f, 0.005f), weak(0.0f, 0.45f);
  std::uniform_int_distribution<int> bits(0, 6), pixel(10, 400);
  std::vector<int> order(2 * n);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);  // slot order[k] holds scene point k (k < n) or clutter
  std::vector<Keypoint> kps(2 * n);
  cv::Mat desc(2 * n, kDescriptorBytes, CV_8U);
  for (int k = 0; k < 2 * n; ++k) {
    const int slot = order[k];
    kps[slot] = {static_cast<double>(pixel(rng)), static_cast<double>(pixel(rng)), 2.0, weak(rng), 0};
    if (k < n && unit(rng) >= replaced) {
      s.descriptors.row(k).copyTo(desc.row(slot));
      synthetic::flip_bits(desc.row(slot), bits(rng), rng);
    } else {
      synthetic::random_descriptors(1, rng).copyTo(desc.row(slot));
    }
    if (k < n) kps[slot].response = s.responses[k] + jitter(rng);
  }
  return synthetic::make_features(kps, desc);
}

TEST(KeyframeDatabase, SignatureTakesStrongestKeypointsTiesByIndex) {
  std::mt19937 rng(1);
  const std::vector<float> responses{0.5f, 2.0f, 1.0f, 2.0f, 0.1f, 1.5f};
  std::vector<Keypoint> kps;
  for (float r : responses) kps.push_back({100, 100, 2.0, r, 0});
  const auto f = synthetic::make_features(kps, synthetic::random_descriptors(6, rng));

  const KeyframeDatabase db(4);
  const cv::Mat sig = db.signature(*f);
  ASSERT_EQ(sig.rows, 4);
  ASSERT_EQ(sig.cols, kDescriptorBytes);
  const int expected[] = {1, 3, 5, 2};  // 2.0 (index 1 before 3), 1.5, 1.0
  for (int r = 0; r < 4; ++r) EXPECT_TRUE(same_row(sig, r, f->descriptors, expected[r])) << "row " << r;
  // Same input, same signature.
  const cv::Mat again = db.signature(*f);
  for (int r = 0; r < 4; ++r) EXPECT_TRUE(same_row(sig, r, again, r));

  // Fewer keypoints than the signature size: all of them, strongest first.
  const cv::Mat all = KeyframeDatabase(100).signature(*f);
  ASSERT_EQ(all.rows, 6);
  EXPECT_TRUE(same_row(all, 5, f->descriptors, 4));
}

/// A database of: 0 unrelated, 1 half of the scene, 2 unrelated, 3 the scene, 4 the scene (same features as 3).
struct PlaceFixture {
  std::mt19937 rng{7};
  Scene scene = make_scene(300, rng);
  KeyframeDatabase db{256};
  std::vector<KeyFramePtr> kfs;
  cv::Mat query;

  PlaceFixture() {
    const Scene other_a = make_scene(300, rng), other_b = make_scene(300, rng);
    const auto same = view_of(scene, 0.1, rng);
    kfs = {keyframe_of(0, view_of(other_a, 0.0, rng)), keyframe_of(1, view_of(scene, 0.5, rng)),
           keyframe_of(2, view_of(other_b, 0.0, rng)), keyframe_of(3, same), keyframe_of(4, same)};
    for (const auto& kf : kfs) db.add(kf);
    query = db.signature(*view_of(scene, 0.0, rng));
  }

  std::vector<long> ids(const std::vector<PlaceCandidate>& c) const {
    std::vector<long> out;
    for (const auto& p : c) out.push_back(p.keyframe->id());
    return out;
  }
};

TEST(KeyframeDatabase, QueryRanksSameSceneAboveUnrelated) {
  PlaceFixture f;
  EXPECT_EQ(f.db.size(), 5u);
  const auto c = f.db.query(f.query, 1, 10);
  // Equal scores (3 and 4 share features) go to the lower id; unrelated keyframes share no strict match.
  ASSERT_EQ(f.ids(c), (std::vector<long>{3, 4, 1}));
  EXPECT_EQ(c[0].score, c[1].score);
  // ~90% of the strongest 256 are shared scene descriptors: a signature built from weak or arbitrary
  // keypoints (half of them clutter) would score near half of that.
  EXPECT_GE(c[0].score, 180);
  EXPECT_LE(c[0].score, 256);
  EXPECT_GT(c[0].score, c[2].score + 50);  // half the scene replaced: clearly lower
  EXPECT_GE(c[2].score, 60);
  EXPECT_EQ(c[0].score, KeyframeDatabase::similarity(f.query, f.db.signature(f.kfs[3]->features())));

  // With no threshold the unrelated ones come last, with (almost) nothing in common.
  const auto all = f.db.query(f.query, 0, 10);
  ASSERT_EQ(all.size(), 5u);
  EXPECT_LE(all[3].score, 3);
  EXPECT_LE(all[4].score, 3);
}

TEST(KeyframeDatabase, MinScoreKeepsOnlyCandidatesReachingIt) {
  PlaceFixture f;
  const auto c = f.db.query(f.query, 1, 10);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(f.ids(f.db.query(f.query, c[2].score, 10)), (std::vector<long>{3, 4, 1}));  // inclusive
  EXPECT_EQ(f.ids(f.db.query(f.query, c[2].score + 1, 10)), (std::vector<long>{3, 4}));
  EXPECT_TRUE(f.db.query(f.query, c[0].score + 1, 10).empty());
}

TEST(KeyframeDatabase, ExcludedAndBadKeyframesAreSkipped) {
  PlaceFixture f;
  std::vector<long> asked;
  const auto c = f.db.query(f.query, 1, 10, [&](const KeyFrame& kf) {
    asked.push_back(kf.id());
    return kf.id() == 3;
  });
  EXPECT_EQ(f.ids(c), (std::vector<long>{4, 1}));
  EXPECT_EQ(asked.size(), 5u);  // every keyframe is offered to the predicate

  f.kfs[4]->set_bad();
  EXPECT_EQ(f.ids(f.db.query(f.query, 1, 10)), (std::vector<long>{3, 1}));
}

TEST(KeyframeDatabase, MaxCandidatesKeepsTheBest) {
  PlaceFixture f;
  EXPECT_EQ(f.ids(f.db.query(f.query, 0, 2)), (std::vector<long>{3, 4}));
  EXPECT_EQ(f.ids(f.db.query(f.query, 0, 1)), (std::vector<long>{3}));
  EXPECT_TRUE(f.db.query(f.query, 0, 0).empty());
  EXPECT_TRUE(KeyframeDatabase(256).query(f.query, 0, 10).empty());  // empty database
}

}  // namespace
}  // namespace varslam::slam
