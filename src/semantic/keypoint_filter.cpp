#include "semantic/keypoint_filter.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace varslam::semantic {
namespace {

constexpr int kMaxSamplesPerBox = 4096;  // plenty for a 0.1 m histogram; keeps a big box cheap

struct BoxDepth {
  cv::Rect rect;
  PersonDepth person;      // whole_m == 0: the box has no valid depth
  cv::Mat dist_to_person;  // per pixel of rect (CV_32F); empty when the silhouette margin is off
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

namespace {

// Depth histogram of a box (one guard bin at each end), from every step-th pixel that no excluded rect covers.
struct DepthHistogram {
  std::vector<int> bins;
  int total = 0;
};

DepthHistogram depth_histogram(const cv::Mat& depth_m, const cv::Rect& roi, const std::vector<cv::Rect>& exclude,
                               const FilterConfig& cfg) {
  const int n_bins = std::max(1, static_cast<int>(std::ceil((cfg.max_depth_m - cfg.min_depth_m) / cfg.bin_m)));
  DepthHistogram h;
  h.bins.assign(static_cast<std::size_t>(n_bins) + 2, 0);
  int step = std::max(1, cfg.sample_step);
  while (roi.area() / (step * step) > kMaxSamplesPerBox) ++step;
  for (int y = roi.y; y < roi.y + roi.height; y += step) {
    const float* row = depth_m.ptr<float>(y);
    for (int x = roi.x; x < roi.x + roi.width; x += step) {
      const float d = row[x];
      if (!valid_depth(d, cfg)) continue;
      const cv::Point p(x, y);
      if (std::any_of(exclude.begin(), exclude.end(), [&](const cv::Rect& r) { return r.contains(p); })) continue;
      const int b = std::min(n_bins - 1, static_cast<int>((d - cfg.min_depth_m) / cfg.bin_m));
      ++h.bins[static_cast<std::size_t>(b) + 1];
      ++h.total;
    }
  }
  return h;
}

// The nearest strong mode of the histogram (the person in front of the background), else the global mode.
float person_depth_from(const DepthHistogram& h, const FilterConfig& cfg) {
  if (h.total == 0) return 0.0f;
  const int n_bins = static_cast<int>(h.bins.size()) - 2;
  // Counts over three neighbouring bins, so a surface straddling a bin edge still forms one peak.
  auto window = [&](int b) {
    const auto i = static_cast<std::size_t>(b);  // bins[i + 1] is bin b
    return h.bins[i] + h.bins[i + 1] + h.bins[i + 2];
  };
  const double strong = cfg.peak_fraction * h.total;
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
    const int c = h.bins[static_cast<std::size_t>(b) + 1];
    sum += c * (cfg.min_depth_m + (b + 0.5) * cfg.bin_m);
    count += c;
  }
  return count > 0 ? static_cast<float>(sum / count) : 0.0f;
}

bool usable(const cv::Mat& depth_m, const FilterConfig& cfg) {
  return !depth_m.empty() && depth_m.type() == CV_32FC1 && cfg.bin_m > 0.0f;
}

}  // namespace

float estimate_person_depth(const cv::Mat& depth_m, const cv::Rect& roi_in, const std::vector<cv::Rect>& exclude,
                            const FilterConfig& cfg) {
  if (!usable(depth_m, cfg)) return 0.0f;
  const cv::Rect roi = roi_in & cv::Rect(0, 0, depth_m.cols, depth_m.rows);
  if (roi.area() <= 0) return 0.0f;
  return person_depth_from(depth_histogram(depth_m, roi, exclude, cfg), cfg);
}

float estimate_person_depth(const cv::Mat& depth_m, const cv::Rect& roi, const FilterConfig& cfg) {
  return estimate_person_depth(depth_m, roi, {}, cfg);
}

std::vector<PersonDepth> estimate_person_depths(const cv::Mat& depth_m, const std::vector<cv::Rect>& rects,
                                                const FilterConfig& cfg) {
  std::vector<PersonDepth> out(rects.size());
  if (!usable(depth_m, cfg)) return out;
  const cv::Rect image(0, 0, depth_m.cols, depth_m.rows);
  for (std::size_t i = 0; i < rects.size(); ++i) {
    const cv::Rect roi = rects[i] & image;
    if (roi.area() <= 0) continue;
    std::vector<cv::Rect> others;
    for (std::size_t j = 0; j < rects.size(); ++j)
      if (j != i && (rects[j] & roi).area() > 0) others.push_back(rects[j]);
    const DepthHistogram whole = depth_histogram(depth_m, roi, {}, cfg);
    out[i].whole_m = person_depth_from(whole, cfg);
    if (others.empty()) continue;
    const DepthHistogram own = depth_histogram(depth_m, roi, others, cfg);
    if (own.total > 0 && own.total >= cfg.min_exclusive_share * whole.total) {
      const float own_m = person_depth_from(own, cfg);
      if (std::abs(own_m - out[i].whole_m) > cfg.depth_band_m) out[i].own_part_m = own_m;
    }
  }
  return out;
}

cv::Mat distance_to_person(const cv::Mat& depth_m, const cv::Rect& roi, const PersonDepth& person,
                           const FilterConfig& cfg) {
  cv::Mat1b not_person(roi.size(), uchar(255));
  for (int y = 0; y < roi.height; ++y) {
    const float* d = depth_m.ptr<float>(roi.y + y) + roi.x;
    uchar* m = not_person.ptr<uchar>(y);
    for (int x = 0; x < roi.width; ++x)
      if (valid_depth(d[x], cfg) && person.matches(d[x], cfg.depth_band_m)) m[x] = 0;
  }
  cv::Mat dist;
  cv::distanceTransform(not_person, dist, cv::DIST_L2, 3);  // distance to the nearest zero (person) pixel
  return dist;
}

PersonRegions locate_people(const cv::Size& image_size, const cv::Mat& depth_m, const Detections& boxes,
                            const FilterConfig& cfg) {
  PersonRegions people;
  people.has_depth = !depth_m.empty() && depth_m.type() == CV_32FC1 && depth_m.size() == image_size;
  for (const auto& b : boxes) {
    const cv::Rect r = enlarge_box(b.box, cfg.box_enlarge, image_size);
    if (r.area() > 0) people.rects.push_back(r);
  }
  people.persons = people.has_depth ? estimate_person_depths(depth_m, people.rects, cfg)
                                    : std::vector<PersonDepth>(people.rects.size());
  return people;
}

cv::Mat allowed_pixels(const cv::Size& image_size, const cv::Mat& depth_m, const Detections& boxes,
                       const FilterConfig& cfg) {
  return allowed_pixels(image_size, depth_m, locate_people(image_size, depth_m, boxes, cfg), cfg);
}

cv::Mat allowed_pixels(const cv::Size& image_size, const cv::Mat& depth_m, const PersonRegions& people,
                       const FilterConfig& cfg) {
  if (people.rects.empty() || image_size.area() <= 0) return {};
  cv::Mat1b allowed(image_size, uchar(255));
  for (std::size_t k = 0; k < people.rects.size(); ++k) {
    const cv::Rect r = people.rects[k] & cv::Rect(0, 0, image_size.width, image_size.height);
    const PersonDepth& person = people.persons[k];
    if (!people.has_depth || person.whole_m <= 0.0f) {  // same rule as filter_keypoints: unknown depth = the person
      allowed(r).setTo(0);
      continue;
    }
    for (int y = r.y; y < r.y + r.height; ++y) {
      const float* d = depth_m.ptr<float>(y);
      uchar* a = allowed.ptr<uchar>(y);
      for (int x = r.x; x < r.x + r.width; ++x)
        if (!valid_depth(d[x], cfg) || person.matches(d[x], cfg.depth_band_m)) a[x] = 0;
    }
  }
  return allowed;
}

std::vector<bool> filter_keypoints(const std::vector<cv::KeyPoint>& kps, const cv::Mat& depth_m,
                                   const Detections& boxes, const FilterConfig& cfg, FilterStats* stats) {
  // Without a depth image there is no image size to clip the boxes to.
  const bool has_depth = !depth_m.empty() && depth_m.type() == CV_32FC1;
  const cv::Size size = has_depth ? depth_m.size() : cv::Size(INT_MAX / 2, INT_MAX / 2);
  return filter_keypoints(kps, depth_m, locate_people(size, depth_m, boxes, cfg), cfg, stats);
}

std::vector<bool> filter_keypoints(const std::vector<cv::KeyPoint>& kps, const cv::Mat& depth_m,
                                   const PersonRegions& people, const FilterConfig& cfg, FilterStats* stats) {
  std::vector<bool> keep(kps.size(), true);
  FilterStats s;
  if (people.rects.empty()) {
    if (stats) *stats = s;
    return keep;
  }
  const bool has_depth = people.has_depth;
  std::vector<BoxDepth> bds;
  for (std::size_t k = 0; k < people.rects.size(); ++k) {
    BoxDepth bd;
    bd.rect = people.rects[k];
    bd.person = people.persons[k];
    if (cfg.silhouette_margin_px > 0.0f && bd.person.whole_m > 0.0f)
      bd.dist_to_person = distance_to_person(depth_m, bd.rect, bd.person, cfg);
    bds.push_back(bd);
  }

  for (std::size_t i = 0; i < kps.size(); ++i) {
    const cv::Point p(static_cast<int>(std::lround(kps[i].pt.x)), static_cast<int>(std::lround(kps[i].pt.y)));
    bool inside = false, no_depth = false, at_person = false, behind = false, in_front = false, on_edge = false;
    // Silhouette margin in pixels at this keypoint's scale (ORB sizes are 31 px times the level's scale).
    const float margin = cfg.silhouette_margin_px * std::max(1.0f, kps[i].size / 31.0f);
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
      } else if (bd.person.whole_m <= 0.0f || bd.person.matches(d, cfg.depth_band_m)) {
        at_person = true;  // an unknown person depth counts as "could be the person"
      } else {
        if (d > bd.person.whole_m) behind = true;
        else in_front = true;
        if (!bd.dist_to_person.empty() && bd.dist_to_person.at<float>(p - bd.rect.tl()) <= margin) on_edge = true;
      }
    }
    if (!inside) continue;
    ++s.in_boxes;
    if (no_depth || at_person || on_edge) {
      keep[i] = false;
      ++s.dropped;
      if (no_depth) ++s.dropped_no_depth;
      else if (!at_person) ++s.dropped_silhouette;
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
