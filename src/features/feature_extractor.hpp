#pragma once
// ORB feature extraction: keypoints over a scale pyramid with rotated-BRIEF descriptors.
// Two implementations behind one interface: our own (spread-out keypoints, see orb_extractor.hpp)
// and a wrapper around cv::ORB with the same parameters, so the two can be compared.
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/setting_keys.hpp"

namespace varslam {

struct OrbParams {
  int n_features = setting_keys::int_default("orb.n_features");  // total keypoint budget over all levels
  double scale_factor = setting_keys::real_default("orb.scale_factor");  // between consecutive pyramid levels
  int n_levels = setting_keys::int_default("orb.n_levels");
  int ini_th_fast = setting_keys::int_default("orb.ini_th_fast");  // FAST threshold tried first in every cell
  int min_th_fast = setting_keys::int_default("orb.min_th_fast");  // where the first one finds nothing
  int threads = setting_keys::int_default("orb.threads");  // our extractor: pyramid levels processed side by side
};

enum class ExtractorKind { Ours, OpenCV };

class FeatureExtractor {
 public:
  virtual ~FeatureExtractor() = default;
  FeatureExtractor(const FeatureExtractor&) = delete;
  FeatureExtractor& operator=(const FeatureExtractor&) = delete;

  /// Keypoints in level-0 pixel coordinates (pt), with octave = pyramid level, angle in degrees [0, 360),
  /// size = patch diameter at level 0; descriptors: CV_8UC1, one 32-byte row per keypoint (rotated BRIEF,
  /// 256 bits). `gray` should be CV_8UC1 (a CV_8UC3 BGR image is converted). Empty input gives no keypoints.
  /// `mask` (optional, CV_8UC1, the image's size): keypoints only where it is non-zero, and the whole budget is
  /// spent there (the semantic filter masks people so the background gets their share). A mask of another size
  /// or type is an std::invalid_argument.
  void extract(const cv::Mat& gray, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors,
               const cv::Mat& mask = cv::Mat());

  int n_levels() const { return params_.n_levels; }
  double scale_factor() const { return params_.scale_factor; }
  const OrbParams& params() const { return params_; }
  const std::vector<double>& scale_factors() const { return scale_; }  // scale of level l = scale_factor^l
  const std::vector<double>& level_sigma2() const { return sigma2_; }  // (scale_factor^l)^2
  const std::vector<double>& inv_level_sigma2() const { return inv_sigma2_; }

 protected:
  /// Validates the parameters (throws varslam::ConfigError) and fills the per-level tables.
  explicit FeatureExtractor(const OrbParams& params);
  /// extract() with the mask checked (empty or CV_8UC1 of the image's size).
  virtual void do_extract(const cv::Mat& gray, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors,
                          const cv::Mat& mask) = 0;

 private:
  OrbParams params_;
  std::vector<double> scale_, sigma2_, inv_sigma2_;
};

std::unique_ptr<FeatureExtractor> make_extractor(const OrbParams& params, ExtractorKind kind = ExtractorKind::Ours);

}  // namespace varslam
