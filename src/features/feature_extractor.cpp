#include "features/feature_extractor.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "features/opencv_orb_extractor.hpp"
#include "features/orb_extractor.hpp"

namespace varslam {

FeatureExtractor::FeatureExtractor(const OrbParams& params) : params_(params) {
  const auto bad = [](const std::string& what) { throw ConfigError("ORB extractor settings: " + what); };
  if (params.n_features < 1) bad("n_features must be >= 1, got " + std::to_string(params.n_features));
  if (params.n_levels < 1 || params.n_levels > 32)
    bad("n_levels must be in [1, 32], got " + std::to_string(params.n_levels));
  if (!(params.scale_factor > 1.0) || params.scale_factor > 4.0)
    bad("scale_factor must be in (1, 4], got " + std::to_string(params.scale_factor));
  if (params.ini_th_fast < 1 || params.ini_th_fast > 254)
    bad("ini_th_fast must be in [1, 254], got " + std::to_string(params.ini_th_fast));
  if (params.min_th_fast < 1 || params.min_th_fast > params.ini_th_fast)
    bad("min_th_fast must be in [1, ini_th_fast], got " + std::to_string(params.min_th_fast));
  if (params.threads < 1 || params.threads > 16)
    bad("threads must be in [1, 16], got " + std::to_string(params.threads));

  for (int l = 0; l < params.n_levels; ++l) {
    const double s = std::pow(params.scale_factor, l);
    scale_.push_back(s);
    sigma2_.push_back(s * s);
    inv_sigma2_.push_back(1.0 / (s * s));
  }
}

void FeatureExtractor::extract(const cv::Mat& gray, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors,
                               const cv::Mat& mask) {
  if (!mask.empty() && (mask.type() != CV_8UC1 || mask.size() != gray.size()))
    throw std::invalid_argument("FeatureExtractor::extract: the mask must be CV_8UC1 of the image's size");
  do_extract(gray, keypoints, descriptors, mask);
}

std::unique_ptr<FeatureExtractor> make_extractor(const OrbParams& params, ExtractorKind kind) {
  if (kind == ExtractorKind::OpenCV) return std::make_unique<OpenCvOrbExtractor>(params);
  return std::make_unique<OrbExtractor>(params);
}

}  // namespace varslam
