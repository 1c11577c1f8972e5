#include "semantic/keypoint_filter.hpp"

#include <algorithm>
#include <climits>
#include <cmath>

namespace varslam::semantic {
namespace {

constexpr int kMaxSamplesPerBox = 4096;  // plenty for a 0.1 m histogram; keeps a big box cheap

struct BoxDepth {
  cv::Rect rect;
  float person_m = 0.0f;  // 0: the box has no valid depth
};

bool valid_depth(float d, const FilterConfig& cfg) {
  return std::isfinite(d) && d >= cfg.min_depth_m && d <= cfg.max_depth_m;
}

}  // namespace

cv::Rect enlarge_box(const cv::Rect2f& box, float fraction, const cv::Size& image_size) {
  const float dx = fraction * box.width, dy = fraction * box.height;
  const cv::Point tl(static_cast<int>(std::floor(box.x - dx)), static_cast<int>(std::floor(box.y - dy)));
  const cv::Point br(static_cast<int>(std::ceil(box.x + box.width + dx)),
                     static_cast<int>(std::ceil(box.y + box.height + dy)));
  return cv::Rect(tl, br) & cv::Rect(0, 0, image_size.width, image_size.height);
}

float estimate_person_depth(const cv::Mat& depth_m, const cv::Rect& roi_in, const FilterConfig& cfg) {
  if (depth_m.empty() || depth_m.type() != CV_32FC1 || cfg.bin_m <= 0.0f) return 0.0f;
  const cv::Rect roi = roi_in & cv::Rect(0, 0, depth_m.cols, depth_m.rows);
  if (roi.area() <= 0) return 0.0f;
  int step = std::max(1, cfg.sample_step);
  while (roi.area() / (step * step) > kMaxSamplesPerBox) ++step;

  const int n_bins = std::max(1, static_cast<int>(std::ceil((cfg.max_depth_m - cfg.min_depth_m) / cfg.bin_m)));
  std::vector<int> hist(static_cast<std::size_t>(n_bins) + 2, 0);  // one guard bin at each end
  int total = 0;
  for (int y = roi.y; y < roi.y + roi.height; y += step) {
    const float* row = depth_m.ptr<float>(y);
    for (int x = roi.x; x < roi.x + roi.width; x += step) {
      const float d = row[x];
      if (!valid_depth(d, cfg)) continue;
      const int b = std::min(n_bins - 1, static_cast<int>((d - cfg.min_depth_m) / cfg.bin_m));
      ++hist[static_cast<std::size_t>(b) + 1];
      ++total;
    }
  }
  if (total == 0) return 0.0f;

  // Counts over three neighbouring bins, so a surface straddling a bin edge still forms one peak.
  auto window = [&](int b) {
    const auto i = static_cast<std::size_t>(b);  // hist[i + 1] is bin b
    return hist[i] + hist[i + 1] + hist[i + 2];
  };
  const double strong = cfg.peak_fraction * total;
  int peak = -1;
  for (int b = 0; b < n_bins; ++b) {
    if (window(b) < strong) continue;
    // First strong bin found: climb to the top of this peak (the person's surface spans several bins).
    peak = b;
    while (peak + 1 < n_bins && window(peak + 1) >= window(peak)) ++peak;
    break;
  }
  if (peak < 0) {  // no strong near mode (cluttered box): take the global mode
    peak = 0;
    for (int b = 1; b < n_bins; ++b)
      if (window(b) > window(peak)) peak = b;
  }
  // Count-weighted centre of the three bins around the peak.
  double sum = 0.0, count = 0.0;
  for (int b = std::max(0, peak - 1); b <= std::min(n_bins - 1, peak + 1); ++b) {
    const int c = hist[static_cast<std::size_t>(b) + 1];
    sum += c * (cfg.min_depth_m + (b + 0.5) * cfg.bin_m);
    count += c;
  }
  return count > 0 ? static_cast<float>(sum / count) : 0.0f;
}

std::vector<bool> filter_keypoints(const std::vector<cv::KeyPoint>& kps, const cv::Mat& depth_m,
                                   const Detections& boxes, const FilterConfig& cfg, FilterStats* stats) {
  std::vector<bool> keep(kps.size(), true);
  FilterStats s;
  if (boxes.empty()) {
    if (stats) *stats = s;
    return keep;
  }
  const bool has_depth = !depth_m.empty() && depth_m.type() == CV_32FC1;
  const cv::Size size = has_depth ? depth_m.size() : cv::Size(INT_MAX / 2, INT_MAX / 2);

  std::vector<BoxDepth> bds;
  bds.reserve(boxes.size());
  for (const auto& b : boxes) {
    BoxDepth bd;
    bd.rect = enlarge_box(b.box, cfg.box_enlarge, size);
    if (bd.rect.area() <= 0) continue;
    bd.person_m = has_depth ? estimate_person_depth(depth_m, bd.rect, cfg) : 0.0f;
    bds.push_back(bd);
  }

  for (std::size_t i = 0; i < kps.size(); ++i) {
    const cv::Point p(static_cast<int>(std::lround(kps[i].pt.x)), static_cast<int>(std::lround(kps[i].pt.y)));
    bool inside = false, no_depth = false, at_person = false, behind = false, in_front = false;
    float d = 0.0f;
    bool d_valid = false;
    for (const auto& bd : bds) {
      if (!bd.rect.contains(p)) continue;
      if (!inside) {
        inside = true;
        if (has_depth && p.x >= 0 && p.y >= 0 && p.x < depth_m.cols && p.y < depth_m.rows) {
          d = depth_m.at<float>(p.y, p.x);
          d_valid = valid_depth(d, cfg);
        }
      }
      if (!d_valid) {
        no_depth = true;
      } else if (bd.person_m <= 0.0f || std::abs(d - bd.person_m) <= cfg.depth_band_m) {
        at_person = true;  // an unknown person depth counts as "could be the person"
      } else if (d > bd.person_m) {
        behind = true;
      } else {
        in_front = true;
      }
    }
    if (!inside) continue;
    ++s.in_boxes;
    if (no_depth || at_person) {
      keep[i] = false;
      ++s.dropped;
      if (no_depth) ++s.dropped_no_depth;
    } else if (behind) {
      ++s.kept_background;
    } else if (in_front) {
      ++s.kept_in_front;
    }
  }
  if (stats) *stats = s;
  return keep;
}

}  // namespace varslam::semantic
