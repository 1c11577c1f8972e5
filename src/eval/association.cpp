#include "eval/association.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <tuple>

namespace varslam {
namespace {

/// Indices sorted by timestamp, keeping only the last pose (in input order) of each repeated timestamp.
std::vector<std::size_t> unique_sorted_indices(const Trajectory& traj) {
  std::vector<std::size_t> idx(traj.size());
  std::iota(idx.begin(), idx.end(), std::size_t{0});
  std::stable_sort(idx.begin(), idx.end(),
                   [&](std::size_t a, std::size_t b) { return traj[a].timestamp < traj[b].timestamp; });
  std::vector<std::size_t> out;
  out.reserve(idx.size());
  for (std::size_t k = 0; k < idx.size(); ++k) {
    const bool repeated_later = k + 1 < idx.size() && traj[idx[k + 1]].timestamp == traj[idx[k]].timestamp;
    if (!repeated_later) out.push_back(idx[k]);
  }
  return out;
}

struct Candidate {
  double diff;
  double ta;
  double tb;
  std::size_t a;  // position in the unique-sorted index list of `first`
  std::size_t b;
};

}  // namespace

std::vector<TimestampMatch> associate_timestamps(const Trajectory& first, const Trajectory& second,
                                                 const AssociationOptions& options) {
  const auto ia = unique_sorted_indices(first);
  const auto ib = unique_sorted_indices(second);
  std::vector<double> tb(ib.size());
  for (std::size_t k = 0; k < ib.size(); ++k) tb[k] = second[ib[k]].timestamp + options.offset;

  // Only stamps within the window can qualify, so a sorted sweep replaces associate.py's all-pairs loop.
  // The window is widened by a hair; the exact test below is the same expression as the Python one.
  std::vector<Candidate> candidates;
  for (std::size_t a = 0; a < ia.size(); ++a) {
    const double ta = first[ia[a]].timestamp;
    const double slack = options.max_difference + 1e-9 * (1.0 + std::abs(ta));
    auto it = std::lower_bound(tb.begin(), tb.end(), ta - slack);
    for (; it != tb.end() && *it <= ta + slack; ++it) {
      const double diff = std::abs(ta - *it);
      if (diff < options.max_difference) {
        const auto b = static_cast<std::size_t>(it - tb.begin());
        candidates.push_back({diff, ta, *it, a, b});
      }
    }
  }
  // Python sorts (diff, a, b) tuples: the same lexicographic order on the timestamp values.
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return std::tie(x.diff, x.ta, x.tb) < std::tie(y.diff, y.ta, y.tb);
  });

  std::vector<bool> used_a(ia.size(), false);
  std::vector<bool> used_b(ib.size(), false);
  std::vector<std::pair<std::size_t, std::size_t>> taken;  // (a, b) positions
  for (const auto& c : candidates) {
    if (used_a[c.a] || used_b[c.b]) continue;
    used_a[c.a] = used_b[c.b] = true;
    taken.emplace_back(c.a, c.b);
  }
  // Sorting positions sorts by (first timestamp, second timestamp), like matches.sort() in Python.
  std::sort(taken.begin(), taken.end());
  std::vector<TimestampMatch> matches;
  matches.reserve(taken.size());
  for (const auto& [a, b] : taken) matches.push_back({ia[a], ib[b]});
  return matches;
}

std::size_t nearest_timestamp_index(const std::vector<double>& sorted_stamps, double t) {
  if (sorted_stamps.empty()) throw std::invalid_argument("nearest_timestamp_index: no timestamps");
  const auto it = std::lower_bound(sorted_stamps.begin(), sorted_stamps.end(), t);
  if (it == sorted_stamps.begin()) return 0;
  if (it == sorted_stamps.end()) return sorted_stamps.size() - 1;
  const auto hi = static_cast<std::size_t>(it - sorted_stamps.begin());
  const std::size_t lo = hi - 1;
  return std::abs(sorted_stamps[hi] - t) < std::abs(sorted_stamps[lo] - t) ? hi : lo;
}

}  // namespace varslam
