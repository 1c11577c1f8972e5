#include "features/orb_extractor.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "features/fast_grid.hpp"
#include "features/image_pyramid.hpp"
#include "features/keypoint_spread.hpp"

namespace varslam {

OrbExtractor::OrbExtractor(const OrbParams& params) : FeatureExtractor(params), orientation_(kOrbPatchRadius) {
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
  build_pyramid(*input, scale_factors(), pyramid_);
  smoothed_.resize(std::size_t(n_levels));
  level_keypoints_.resize(std::size_t(n_levels));
  const FastGridParams grid{kGridCell, params().ini_th_fast, params().min_th_fast};

  std::size_t total = 0;
  int carry = 0;  // budget left unused by the finer levels
  for (int l = 0; l < n_levels; ++l) {
    const auto lu = std::size_t(l);
    auto& found = level_keypoints_[lu];
    found.clear();
    const int budget = budgets_[lu] + carry;
    const cv::Mat& image = pyramid_[lu];
    const cv::Rect region(kEdge, kEdge, image.cols - 2 * kEdge, image.rows - 2 * kEdge);
    if (image.empty() || region.width <= 0 || region.height <= 0 || budget <= 0) {
      carry = budget;
      continue;
    }
    candidates_.clear();
    detect_fast_grid(image, region, grid, candidates_);
    if (!mask.empty()) {
      // Masked corners leave before the spreading, so the level's budget goes to the allowed area.
      std::erase_if(candidates_, [&](const cv::KeyPoint& c) {
        const int x = std::clamp(static_cast<int>(level_to_base(c.pt.x, input->cols, image.cols)), 0, mask.cols - 1);
        const int y = std::clamp(static_cast<int>(level_to_base(c.pt.y, input->rows, image.rows)), 0, mask.rows - 1);
        return mask.at<std::uint8_t>(y, x) == 0;
      });
    }
    const std::vector<cv::KeyPoint> kept = spread_keypoints(candidates_, region, budget);
    found.reserve(kept.size());
    for (const cv::KeyPoint& kp : kept) {
      const int x = static_cast<int>(kp.pt.x), y = static_cast<int>(kp.pt.y);
      found.push_back({x, y, orientation_.angle_deg(image, x, y), kp.response});
    }
    carry = budget - static_cast<int>(found.size());
    total += found.size();
    // The descriptor compares single pixels, so it reads a smoothed image to be robust to noise.
    if (!found.empty()) cv::GaussianBlur(image, smoothed_[lu], cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
  }

  descriptors.create(static_cast<int>(total), 32, CV_8UC1);
  keypoints.reserve(total);
  int row = 0;
  for (int l = 0; l < n_levels; ++l) {
    const auto lu = std::size_t(l);
    const cv::Mat& image = pyramid_[lu];
    const float size = static_cast<float>(2 * kOrbPatchRadius + 1) * static_cast<float>(scale_factors()[lu]);
    for (const LevelKeypoint& k : level_keypoints_[lu]) {
      const cv::Point2f pt(level_to_base(float(k.x), input->cols, image.cols),
                           level_to_base(float(k.y), input->rows, image.rows));
      keypoints.emplace_back(pt, size, k.angle, k.response, l);
      rotated_brief(smoothed_[lu], k.x, k.y, k.angle, descriptors.ptr<std::uint8_t>(row++));
    }
  }
}

}  // namespace varslam
