#include "io/frame_list.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "io/text_lines.hpp"

namespace varslam {
namespace {

// Calls fn(tokens, where, line) for each non-comment line.
template <typename Fn>
void for_each_line(const std::filesystem::path& file, Fn&& fn) {
  for_each_data_line(file, "list file", [&](const TextLine& l) { fn(l.tokens, l.where, *l.text); });
}

double timestamp_or_throw(const std::string& token, const std::string& where, const std::string& line,
                          const char* expected) {
  double t = 0;
  if (!parse_double(token, t))
    throw InputError(fmt::format("{}: expected '{}', got '{}'", where, expected, line));
  if (!std::isfinite(t)) throw InputError(fmt::format("{}: timestamp '{}' is not a finite number", where, token));
  return t;
}

void check_increasing(const std::vector<ListEntry>& entries, const ListEntry& next) {
  if (entries.empty() || next.timestamp > entries.back().timestamp) return;
  throw InputError(fmt::format("{}: timestamp {:.6f} is not after {:.6f} ({}); list timestamps must strictly "
                               "increase",
                               next.where, next.timestamp, entries.back().timestamp, entries.back().where));
}

}  // namespace

std::vector<ListEntry> read_frame_list(const std::filesystem::path& file) {
  std::vector<ListEntry> out;
  for_each_line(file, [&](const std::vector<std::string>& tok, const std::string& where, const std::string& line) {
    constexpr const char* kExpected = "timestamp path";
    if (tok.size() != 2) throw InputError(fmt::format("{}: expected '{}', got '{}'", where, kExpected, line));
    ListEntry e{timestamp_or_throw(tok[0], where, line, kExpected), tok[1], where};
    check_increasing(out, e);
    out.push_back(std::move(e));
  });
  return out;
}

std::vector<FramePair> read_associations(const std::filesystem::path& file) {
  std::vector<FramePair> out;
  std::vector<ListEntry> rgb;  // for the ordering check
  for_each_line(file, [&](const std::vector<std::string>& tok, const std::string& where, const std::string& line) {
    constexpr const char* kExpected = "t_rgb rgb_path t_depth depth_path";
    if (tok.size() != 4) throw InputError(fmt::format("{}: expected '{}', got '{}'", where, kExpected, line));
    FramePair p{{timestamp_or_throw(tok[0], where, line, kExpected), tok[1], where},
                {timestamp_or_throw(tok[2], where, line, kExpected), tok[3], where}};
    check_increasing(rgb, p.rgb);
    rgb.push_back(p.rgb);
    out.push_back(std::move(p));
  });
  return out;
}

std::vector<FramePair> associate_frames(const std::vector<ListEntry>& rgb, const std::vector<ListEntry>& depth,
                                        double max_dt) {
  struct Candidate {
    double dt;
    std::size_t r, d;
  };
  // Sorted lists: the depth window of each rgb stamp is found with a moving lower bound. The window is tested
  // on differences, not on t +- max_dt, which rounds back to t for large stamps.
  std::vector<Candidate> candidates;
  std::size_t lo = 0;
  for (std::size_t r = 0; r < rgb.size(); ++r) {
    while (lo < depth.size() && rgb[r].timestamp - depth[lo].timestamp >= max_dt) ++lo;
    for (std::size_t d = lo; d < depth.size() && depth[d].timestamp - rgb[r].timestamp < max_dt; ++d)
      candidates.push_back({std::abs(rgb[r].timestamp - depth[d].timestamp), r, d});
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.dt < b.dt; });
  std::vector<bool> rgb_used(rgb.size(), false), depth_used(depth.size(), false);
  std::vector<std::pair<std::size_t, std::size_t>> matches;
  for (const auto& c : candidates) {
    if (rgb_used[c.r] || depth_used[c.d]) continue;
    rgb_used[c.r] = depth_used[c.d] = true;
    matches.emplace_back(c.r, c.d);
  }
  std::sort(matches.begin(), matches.end());
  std::vector<FramePair> out;
  out.reserve(matches.size());
  for (const auto& [r, d] : matches) out.push_back({rgb[r], depth[d]});
  return out;
}

}  // namespace varslam
