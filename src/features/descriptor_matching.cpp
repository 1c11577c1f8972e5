#include "features/descriptor_matching.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

// The build targets baseline x86-64, where std::popcount is a slow bit-twiddling sequence. On GCC/x86-64
// the hot functions get a second, POPCNT-instruction version, chosen once at load time by the CPU. Not under
// ThreadSanitizer or AddressSanitizer: their instrumented load-time resolver runs before the sanitizer starts.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(__SANITIZE_THREAD__) && \
    !defined(__SANITIZE_ADDRESS__)
#define VARSLAM_POPCNT_CLONES __attribute__((target_clones("popcnt", "default")))
#else
#define VARSLAM_POPCNT_CLONES
#endif

namespace varslam {

VARSLAM_POPCNT_CLONES int descriptor_distance(const std::uint8_t* a, const std::uint8_t* b) {
  int d = 0;
  for (int w = 0; w < kDescriptorBytes / 8; ++w) {
    std::uint64_t x, y;  // memcpy: the rows need not be 8-byte aligned
    std::memcpy(&x, a + 8 * w, 8);
    std::memcpy(&y, b + 8 * w, 8);
    d += std::popcount(x ^ y);
  }
  return d;
}

namespace {

/// Best and second-best distance of `query` over `rows` train rows `stride` bytes apart.
struct BestTwo {
  int best, second, best_index;
};

VARSLAM_POPCNT_CLONES BestTwo scan_rows(const std::uint8_t* query, const std::uint8_t* train, std::size_t stride,
                                        int rows) {
  std::uint64_t q[4];
  std::memcpy(q, query, 32);
  BestTwo r{std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), -1};
  for (int t = 0; t < rows; ++t, train += stride) {
    std::uint64_t w[4];
    std::memcpy(w, train, 32);  // memcpy: rows need not be 8-byte aligned
    const int d = std::popcount(q[0] ^ w[0]) + std::popcount(q[1] ^ w[1]) + std::popcount(q[2] ^ w[2]) +
                  std::popcount(q[3] ^ w[3]);
    if (d < r.best) {
      r.second = r.best;
      r.best = d;
      r.best_index = t;
    } else if (d < r.second) {
      r.second = d;
    }
  }
  return r;
}

void check_descriptors(const cv::Mat& m, const char* what) {
  if (m.type() != CV_8UC1 || (m.cols != kDescriptorBytes && !m.empty()))
    throw std::invalid_argument(std::string(what) + ": expected rows of 32 CV_8U bytes");
}
}  // namespace

int descriptor_distance(const cv::Mat& a, const cv::Mat& b) {
  check_descriptors(a, "descriptor_distance");
  check_descriptors(b, "descriptor_distance");
  if (a.rows != 1 || b.rows != 1) throw std::invalid_argument("descriptor_distance: expected 1x32 rows");
  return descriptor_distance(a.ptr<std::uint8_t>(0), b.ptr<std::uint8_t>(0));
}

std::vector<DescriptorMatch> match_descriptors(const cv::Mat& query, const cv::Mat& train, int max_distance,
                                               double ratio, bool unique) {
  check_descriptors(query, "match_descriptors (query)");
  check_descriptors(train, "match_descriptors (train)");
  std::vector<DescriptorMatch> matches;
  if (query.empty() || train.empty()) return matches;
  const bool use_ratio = ratio < 1.0;
  for (int q = 0; q < query.rows; ++q) {
    const BestTwo r = scan_rows(query.ptr<std::uint8_t>(q), train.ptr<std::uint8_t>(0), train.step[0], train.rows);
    const int best = r.best, second = r.second, best_t = r.best_index;
    if (best > max_distance) continue;
    if (use_ratio && train.rows > 1 && !(best < ratio * second)) continue;
    matches.push_back({q, best_t, best});
  }
  if (unique) {
    // Per train row, the best query: lowest distance, then lowest query index.
    std::vector<int> owner(std::size_t(train.rows), -1);
    for (std::size_t i = 0; i < matches.size(); ++i) {
      int& o = owner[std::size_t(matches[i].train)];
      if (o < 0 || matches[i].distance < matches[std::size_t(o)].distance) o = static_cast<int>(i);
    }
    std::vector<DescriptorMatch> kept;
    for (std::size_t i = 0; i < matches.size(); ++i)
      if (owner[std::size_t(matches[i].train)] == static_cast<int>(i)) kept.push_back(matches[i]);
    matches.swap(kept);
  }
  return matches;
}

std::vector<int> rotation_consistent(const std::vector<float>& angle_differences_deg) {
  constexpr int kBins = 30;
  constexpr float kBinWidth = 360.f / kBins;
  std::vector<int> bin_of(angle_differences_deg.size());
  std::array<int, kBins> count{};
  for (std::size_t i = 0; i < angle_differences_deg.size(); ++i) {
    float a = std::fmod(angle_differences_deg[i], 360.f);
    if (a < 0.f) a += 360.f;
    const int b = std::min(kBins - 1, static_cast<int>(a / kBinWidth));  // a == 360 - eps may round up
    bin_of[i] = b;
    ++count[std::size_t(b)];
  }
  // The three most populated non-empty bins; ties go to the lower bin.
  std::array<int, kBins> order{};
  for (int b = 0; b < kBins; ++b) order[std::size_t(b)] = b;
  std::stable_sort(order.begin(), order.end(),
                   [&](int x, int y) { return count[std::size_t(x)] > count[std::size_t(y)]; });
  std::array<bool, kBins> keep{};
  for (int k = 0; k < 3; ++k)
    if (count[std::size_t(order[std::size_t(k)])] > 0) keep[std::size_t(order[std::size_t(k)])] = true;
  std::vector<int> kept;
  for (std::size_t i = 0; i < bin_of.size(); ++i)
    if (keep[std::size_t(bin_of[i])]) kept.push_back(static_cast<int>(i));
  return kept;
}

int medoid_descriptor(const std::vector<cv::Mat>& descriptors) {
  const std::size_t n = descriptors.size();
  if (n == 0) return -1;
  if (n <= 2) return 0;  // one or two: every choice is as central as the other
  for (const cv::Mat& d : descriptors) {
    check_descriptors(d, "medoid_descriptor");
    if (d.rows != 1) throw std::invalid_argument("medoid_descriptor: expected 1x32 rows");
  }
  std::vector<int> dist(n * n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      dist[i * n + j] = dist[j * n + i] =
          descriptor_distance(descriptors[i].ptr<std::uint8_t>(0), descriptors[j].ptr<std::uint8_t>(0));
  int best = 0, best_median = std::numeric_limits<int>::max();
  std::vector<int> others(n - 1);
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t k = 0;
    for (std::size_t j = 0; j < n; ++j)
      if (j != i) others[k++] = dist[i * n + j];
    // Lower median of the n-1 distances to the others.
    const auto mid = others.begin() + static_cast<std::ptrdiff_t>((others.size() - 1) / 2);
    std::nth_element(others.begin(), mid, others.end());
    if (*mid < best_median) {
      best_median = *mid;
      best = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace varslam
