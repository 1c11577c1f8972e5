#include "slam/keyframe_database.hpp"

#include <algorithm>
#include <numeric>

#include "features/descriptor_matching.hpp"
#include "slam/matcher.hpp"

namespace varslam::slam {

cv::Mat KeyframeDatabase::signature(const FrameFeatures& f) const {
  std::vector<int> order(f.size());
  std::iota(order.begin(), order.end(), 0);
  const auto n = std::min<std::size_t>(order.size(), static_cast<std::size_t>(signature_size_));
  // Strongest first; ties by index so the signature is deterministic.
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(n), order.end(), [&](int a, int b) {
    const float ra = f.keypoints[a].response, rb = f.keypoints[b].response;
    return ra != rb ? ra > rb : a < b;
  });
  cv::Mat sig(static_cast<int>(n), kDescriptorBytes, CV_8U);
  for (std::size_t r = 0; r < n; ++r) f.descriptors.row(order[r]).copyTo(sig.row(static_cast<int>(r)));
  return sig;
}

void KeyframeDatabase::add(const KeyFramePtr& kf) {
  Entry e{kf, signature(kf->features())};
  std::lock_guard lock(mutex_);
  entries_.push_back(std::move(e));
}

void KeyframeDatabase::add(const KeyFramePtr& kf, cv::Mat signature) {
  std::lock_guard lock(mutex_);
  entries_.push_back({kf, std::move(signature)});
}

cv::Mat KeyframeDatabase::signature_of(const KeyFrame& kf) const {
  std::lock_guard lock(mutex_);
  for (const Entry& e : entries_)
    if (e.keyframe.get() == &kf) return e.signature;
  return {};
}

std::size_t KeyframeDatabase::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

int KeyframeDatabase::similarity(const cv::Mat& a, const cv::Mat& b) {
  if (a.empty() || b.empty()) return 0;
  // Strict distance and ratio test: signatures of unrelated places share few such matches.
  return static_cast<int>(match_descriptors(a, b, kDescDistLow, 0.8, true).size());
}

std::vector<PlaceCandidate> KeyframeDatabase::query(const cv::Mat& query_signature, int min_score,
                                                    std::size_t max_candidates,
                                                    const std::function<bool(const KeyFrame&)>& exclude) const {
  std::vector<Entry> entries;
  {
    std::lock_guard lock(mutex_);
    entries = entries_;
  }
  std::vector<PlaceCandidate> out;
  for (const Entry& e : entries) {
    if (e.keyframe->is_bad() || (exclude && exclude(*e.keyframe))) continue;
    const int s = similarity(query_signature, e.signature);
    if (s >= min_score) out.push_back({e.keyframe, s});
  }
  std::stable_sort(out.begin(), out.end(), [](const PlaceCandidate& a, const PlaceCandidate& b) {
    return a.score != b.score ? a.score > b.score : a.keyframe->id() < b.keyframe->id();
  });
  if (out.size() > max_candidates) out.resize(max_candidates);
  return out;
}

}  // namespace varslam::slam
