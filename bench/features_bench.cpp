// ORB extraction: our extractor vs cv::ORB with the same parameters, on real frames (7-Scenes redkitchen)
// or, when the shared data is absent, a synthetic textured image. Counters report the keypoint count and
// how evenly keypoints cover the image: `occupancy` = share of 16x12 grid cells holding a keypoint,
// `cell_cv` = coefficient of variation of keypoints per cell (lower = more even).
// OpenCV runs single-threaded (cv::setNumThreads(1)) so CPU time is the whole cost and both sides compare fairly.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "features/descriptor_matching.hpp"
#include "features/feature_extractor.hpp"

namespace {

using varslam::ExtractorKind;

cv::Mat synthetic_image(int seed) {
  cv::RNG rng(std::uint64_t(seed) + 1);
  cv::Mat img(480, 640, CV_8UC1, cv::Scalar(128));
  for (int i = 0; i < 800; ++i) {
    const cv::Point c(rng.uniform(0, 640), rng.uniform(0, 480));
    const int s = rng.uniform(3, 25);
    if (rng.uniform(0, 2))
      cv::rectangle(img, cv::Rect(c.x, c.y, s, rng.uniform(3, 25)), cv::Scalar(rng.uniform(0, 256)), cv::FILLED);
    else
      cv::circle(img, c, s / 2, cv::Scalar(rng.uniform(0, 256)), cv::FILLED, cv::LINE_AA);
  }
  cv::GaussianBlur(img, img, cv::Size(3, 3), 0.8);
  return img;
}

// Ten frames spread over the sequence, or synthetic stand-ins.
const std::vector<cv::Mat>& frames(bool real) {
  static const std::vector<cv::Mat> real_frames = [] {
    std::vector<cv::Mat> v;
    for (int i = 0; i < 1000; i += 100) {
      char name[64];
      std::snprintf(name, sizeof name, "/realdata/7scenes_redkitchen/rgb/frame-%06d.color.jpg", i);
      const std::string path = std::string(VARSLAM_SHARED_DIR) + name;
      if (std::filesystem::exists(path)) v.push_back(cv::imread(path, cv::IMREAD_GRAYSCALE));
    }
    return v;
  }();
  static const std::vector<cv::Mat> synthetic = [] {
    std::vector<cv::Mat> v;
    for (int i = 0; i < 3; ++i) v.push_back(synthetic_image(i));
    return v;
  }();
  return real ? real_frames : synthetic;
}

struct Spread {
  double occupancy = 0, cell_cv = 0;
};

Spread spread_of(const std::vector<cv::KeyPoint>& kps, cv::Size size) {
  constexpr int kCols = 16, kRows = 12;
  std::vector<double> count(kCols * kRows, 0.0);
  for (const auto& k : kps) {
    const int c = std::clamp(int(k.pt.x * kCols / size.width), 0, kCols - 1);
    const int r = std::clamp(int(k.pt.y * kRows / size.height), 0, kRows - 1);
    count[std::size_t(r * kCols + c)] += 1.0;
  }
  double mean = 0, occupied = 0;
  for (double n : count) mean += n, occupied += n > 0;
  mean /= double(count.size());
  double var = 0;
  for (double n : count) var += (n - mean) * (n - mean);
  var /= double(count.size());
  return {occupied / double(count.size()), mean > 0 ? std::sqrt(var) / mean : 0.0};
}

void BM_Extract(benchmark::State& state, ExtractorKind kind, bool real) {
  cv::setNumThreads(1);
  const auto& images = frames(real);
  if (images.empty()) {
    state.SkipWithError("shared real frames not found");
    return;
  }
  auto ex = varslam::make_extractor(varslam::OrbParams{}, kind);
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  std::size_t i = 0;
  for (auto _ : state) {
    ex->extract(images[i++ % images.size()], kps, desc);
    benchmark::DoNotOptimize(desc.data);
  }
  // Spread measured once per frame, outside the timed loop.
  double n = 0, occ = 0, cv_sum = 0;
  for (const cv::Mat& img : images) {
    ex->extract(img, kps, desc);
    const Spread s = spread_of(kps, img.size());
    n += double(kps.size());
    occ += s.occupancy;
    cv_sum += s.cell_cv;
  }
  const double m = double(images.size());
  state.counters["keypoints"] = n / m;
  state.counters["occupancy"] = occ / m;
  state.counters["cell_cv"] = cv_sum / m;
}

BENCHMARK_CAPTURE(BM_Extract, ours_real, ExtractorKind::Ours, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Extract, opencv_real, ExtractorKind::OpenCV, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Extract, ours_synthetic, ExtractorKind::Ours, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Extract, opencv_synthetic, ExtractorKind::OpenCV, false)->Unit(benchmark::kMillisecond);

// Brute-force matching of two frames' descriptors (about 1000 x 1000), as tracking by descriptor would do.
void BM_MatchDescriptors(benchmark::State& state) {
  cv::setNumThreads(1);
  const auto& real = frames(true);
  const auto& images = real.size() >= 2 ? real : frames(false);
  auto ex = varslam::make_extractor(varslam::OrbParams{});
  std::vector<cv::KeyPoint> ka, kb;
  cv::Mat da, db;
  ex->extract(images[0], ka, da);
  ex->extract(images[1], kb, db);
  std::size_t matches = 0;
  for (auto _ : state) {
    const auto m = varslam::match_descriptors(da, db, 50, 0.8, true);
    matches = m.size();
    benchmark::DoNotOptimize(m.data());
  }
  state.counters["query"] = da.rows;
  state.counters["train"] = db.rows;
  state.counters["matches"] = double(matches);
}
BENCHMARK(BM_MatchDescriptors)->Unit(benchmark::kMillisecond);

// Match quality on real frame pairs (f, f+5 for f = 0, 50, ..., 850): descriptor matches (max distance 50,
// ratio 0.8, unique) and how many of them a RANSAC fundamental matrix (1 px) keeps. One iteration: the
// counters are the point, not the time.
void BM_FramePairInliers(benchmark::State& state, ExtractorKind kind) {
  cv::setNumThreads(1);
  const auto path = [](int i) {
    char name[80];
    std::snprintf(name, sizeof name, "/realdata/7scenes_redkitchen/rgb/frame-%06d.color.jpg", i);
    return std::string(VARSLAM_SHARED_DIR) + name;
  };
  if (!std::filesystem::exists(path(0))) {
    state.SkipWithError("shared real frames not found");
    return;
  }
  auto ex = varslam::make_extractor(varslam::OrbParams{}, kind);
  double matches = 0, inliers = 0, pairs = 0;
  for (auto _ : state) {
    for (int f = 0; f < 900 && std::filesystem::exists(path(f + 5)); f += 50) {
      std::vector<cv::KeyPoint> ka, kb;
      cv::Mat da, db;
      ex->extract(cv::imread(path(f), cv::IMREAD_GRAYSCALE), ka, da);
      ex->extract(cv::imread(path(f + 5), cv::IMREAD_GRAYSCALE), kb, db);
      const auto m = varslam::match_descriptors(da, db, 50, 0.8, true);
      std::vector<cv::Point2f> pa, pb;
      for (const auto& x : m) {
        pa.push_back(ka[std::size_t(x.query)].pt);
        pb.push_back(kb[std::size_t(x.train)].pt);
      }
      if (pa.size() >= 8) {
        cv::Mat mask;
        cv::findFundamentalMat(pa, pb, cv::FM_RANSAC, 1.0, 0.999, mask);
        inliers += cv::countNonZero(mask);
      }
      matches += double(m.size());
      pairs += 1;
    }
  }
  state.counters["matches"] = matches / std::max(1.0, pairs);
  state.counters["f_inliers"] = inliers / std::max(1.0, pairs);
}
BENCHMARK_CAPTURE(BM_FramePairInliers, ours, ExtractorKind::Ours)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FramePairInliers, opencv, ExtractorKind::OpenCV)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
