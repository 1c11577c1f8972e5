#pragma once
// Place recognition without a vocabulary: each keyframe keeps a signature (its strongest ORB descriptors), and a
// query ranks keyframes by how many signature descriptors match the query's one-to-one. Loop detection and
// relocalization ask it for candidates; geometry (keyframe_localization.hpp) then decides.
//
// Why no bag of words: a vocabulary must be trained on and shipped with the data, and its quantisation loses
// matches on small maps. The price is linear search, ~0.1 ms per keyframe compared (256 descriptors): fine for
// rooms and minutes of video, too slow for maps of thousands of keyframes (a vocabulary is the next step there).
// 256 descriptors separate places as well as 1000 at a sixteenth of the cost (BENCHMARKS.md, "Why the defaults").
#include <functional>
#include <mutex>
#include <opencv2/core.hpp>
#include <vector>

#include "slam/keyframe.hpp"

namespace varslam::slam {

struct PlaceCandidate {
  KeyFramePtr keyframe;
  int score = 0;  // one-to-one signature matches
};

class KeyframeDatabase {
 public:
  explicit KeyframeDatabase(int signature_size = 256) : signature_size_(signature_size) {}

  /// Signature of a set of features: the descriptors of the `signature_size` strongest keypoints.
  cv::Mat signature(const FrameFeatures& f) const;

  void add(const KeyFramePtr& kf);
  /// Adds with a signature computed before (a loaded map's).
  void add(const KeyFramePtr& kf, cv::Mat signature);
  /// The signature stored for a keyframe; empty when it is not in the database.
  cv::Mat signature_of(const KeyFrame& kf) const;
  std::size_t size() const;

  /// Keyframes (not bad, not excluded) whose signature matches `query_signature` in at least `min_score`
  /// descriptors, best first (ties: lower id), at most `max_candidates`.
  std::vector<PlaceCandidate> query(const cv::Mat& query_signature, int min_score, std::size_t max_candidates,
                                    const std::function<bool(const KeyFrame&)>& exclude = {}) const;

  /// Signature matches between two signatures (the score of query()).
  static int similarity(const cv::Mat& a, const cv::Mat& b);

 private:
  struct Entry {
    KeyFramePtr keyframe;
    cv::Mat signature;
  };
  int signature_size_;
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;
};

}  // namespace varslam::slam
