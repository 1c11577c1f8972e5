#include "features/orb_extractor.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "features/fast_grid.hpp"
#include "features/image_pyramid.hpp"
#include "features/keypoint_spread.hpp"

namespace varslam {

OrbExtractor::OrbExtractor(const OrbParams& params)
    : FeatureExtractor(params),
      orientation_(kOrbPatchRadius),
      pool_(params.threads > 1 ? std::make_unique<TaskPool>(params.threads) : nullptr) {
  // Share of level l in the series 1, r, r^2, ... (r = 1/s^2), rounded cumulatively so the budgets sum to
  // n_features exactly.
  const double r = 1.0 / (params.scale_factor * params.scale_factor);
  const double total = (1.0 - std::pow(r, params.n_levels)) / (1.0 - r);
  double cumulative = 0.0;
  int assigned = 0;
  for (int l = 0; l < params.n_levels; ++l) {
    cumulative += std::pow(r, l) / total;
    const int upto = l + 1 == params.n_levels ? params.n_features
                                              : static_cast<int>(std::lround(cumulative * params.n_features));
    budgets_.push_back(upto - assigned);
    assigned = upto;
  }
}

cv::Rect OrbExtractor::level_region(int level) const {
  const cv::Mat& image = pyramid_[std::size_t(level)];
  return {kEdge, kEdge, image.cols - 2 * kEdge, image.rows - 2 * kEdge};
}

void OrbExtractor::find_corners(int level, const cv::Mat& mask, cv::Size base) {
  const auto lu = std::size_t(level);
  auto& candidates = candidates_[lu];
  candidates.clear();
  const cv::Mat& image = pyramid_[lu];
  const cv::Rect region = level_region(level);
  if (image.empty() || region.width <= 0 || region.height <= 0) return;
  detect_fast_grid(image, region, {kGridCell, params().ini_th_fast, params().min_th_fast}, candidates);
  if (!mask.empty()) {
    // Masked corners leave before the spreading, so the level's budget goes to the allowed area.
    std::erase_if(candidates, [&](const cv::KeyPoint& c) {
      const int x = std::clamp(static_cast<int>(level_to_base(c.pt.x, base.width, image.cols)), 0, mask.cols - 1);
      const int y = std::clamp(static_cast<int>(level_to_base(c.pt.y, base.height, image.rows)), 0, mask.rows - 1);
      return mask.at<std::uint8_t>(y, x) == 0;
    });
  }
  // The descriptor compares single pixels, so it reads a smoothed image to be robust to noise.
  if (!candidates.empty()) cv::GaussianBlur(image, smoothed_[lu], cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
}

void OrbExtractor::describe_level(int level, cv::Size base, std::vector<cv::KeyPoint>& keypoints,
                                  cv::Mat& descriptors) const {
  const auto lu = std::size_t(level);
  if (level_kept_[lu] == 0) return;
  const cv::Mat& image = pyramid_[lu];
  const std::vector<cv::KeyPoint> kept = spread_keypoints(candidates_[lu], level_region(level), level_budget_[lu]);
  const float size = static_cast<float>(2 * kOrbPatchRadius + 1) * static_cast<float>(scale_factors()[lu]);
  int row = first_row_[lu];
  for (const cv::KeyPoint& kp : kept) {
    const int x = static_cast<int>(kp.pt.x), y = static_cast<int>(kp.pt.y);
    const float angle = orientation_.angle_deg(image, x, y);
    const cv::Point2f pt(level_to_base(float(x), base.width, image.cols), level_to_base(float(y), base.height, image.rows));
    keypoints[std::size_t(row)] = cv::KeyPoint(pt, size, angle, kp.response, level);
    rotated_brief(smoothed_[lu], x, y, angle, descriptors.ptr<std::uint8_t>(row++));
  }
}

void OrbExtractor::do_extract(const cv::Mat& gray, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors,
                              const cv::Mat& mask) {
  keypoints.clear();
  if (gray.empty()) {
    descriptors.create(0, 32, CV_8UC1);
    return;
  }
  const cv::Mat* input = &gray;
  if (gray.type() == CV_8UC3) {
    cv::cvtColor(gray, gray_buffer_, cv::COLOR_BGR2GRAY);
    input = &gray_buffer_;
  } else if (gray.type() != CV_8UC1) {
    throw std::invalid_argument("OrbExtractor::extract: expected a CV_8UC1 (or CV_8UC3) image");
  }

  const int n_levels = this->n_levels();
  const auto levels = std::size_t(n_levels);
  const cv::Size base = input->size();
  build_pyramid(*input, scale_factors(), pyramid_);
  smoothed_.resize(levels);
  candidates_.resize(levels);
  level_budget_.assign(levels, 0);
  level_kept_.assign(levels, 0);
  first_row_.assign(levels, 0);
  // Level 0 first: the largest level starts first, so the threads finish close together.
  const auto run = [&](const std::function<void(int)>& task) {
    if (pool_)
      pool_->run(n_levels, task);
    else
      for (int l = 0; l < n_levels; ++l) task(l);
  };
  run([&](int l) { find_corners(l, mask, base); });

  // A level keeps min(corners, budget) (spread_keypoints' contract), so every level's share and first row are
  // known from the corner counts alone; the unused budget of the finer levels carries on to the coarser.
  int carry = 0, total = 0;
  for (std::size_t l = 0; l < levels; ++l) {
    const int budget = budgets_[l] + carry;
    const cv::Rect region = level_region(int(l));
    const bool usable = !pyramid_[l].empty() && region.width > 0 && region.height > 0 && budget > 0;
    level_budget_[l] = budget;
    level_kept_[l] = usable ? std::min(static_cast<int>(candidates_[l].size()), budget) : 0;
    first_row_[l] = total;
    total += level_kept_[l];
    carry = budget - level_kept_[l];
  }

  descriptors.create(total, 32, CV_8UC1);
  keypoints.resize(std::size_t(total));
  run([&](int l) { describe_level(l, base, keypoints, descriptors); });
}

}  // namespace varslam
