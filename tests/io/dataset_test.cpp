#include "io/dataset.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "core/error.hpp"
#include "io/depth_image.hpp"
#include "io/frame_list.hpp"
#include "io/temp_dir.hpp"

namespace varslam {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using varslam::testing::TempDir;
namespace fs = std::filesystem;

constexpr int kW = 32, kH = 24;

Settings tiny_settings(double depth_factor = 5000.0) {
  Settings s = default_settings();
  s.camera.width = kW;
  s.camera.height = kH;
  s.depth_factor = depth_factor;
  return s;
}

void write_rgb(const fs::path& p, cv::Scalar bgr = {10, 200, 50}, int w = kW, int h = kH) {
  fs::create_directories(p.parent_path());
  ASSERT_TRUE(cv::imwrite(p.string(), cv::Mat(h, w, CV_8UC3, bgr)));
}

// Mostly `value`, with a "no depth" 0 at (0,0) and the 65535 marker at (1,0).
void write_depth(const fs::path& p, std::uint16_t value = 10000, int w = kW, int h = kH) {
  fs::create_directories(p.parent_path());
  cv::Mat d(h, w, CV_16UC1, cv::Scalar(value));
  d.at<std::uint16_t>(0, 0) = 0;
  d.at<std::uint16_t>(0, 1) = 65535;
  ASSERT_TRUE(cv::imwrite(p.string(), d));
}

// A TUM-layout folder with n frames at 30 Hz, depth stamped 5 ms after colour.
void make_tum(const TempDir& dir, int n, std::uint16_t depth_value = 10000) {
  std::string rgb = "# color images\n# timestamp filename\n", depth = "# depth\n";
  for (int i = 0; i < n; ++i) {
    const double t = 100.0 + i / 30.0;
    const std::string name = fmt::format("{:.6f}.png", t);
    write_rgb(dir / ("rgb/" + name));
    write_depth(dir / ("depth/" + name), depth_value);
    rgb += fmt::format("{:.6f} rgb/{}\n", t, name);
    depth += fmt::format("{:.6f} depth/{}\n", t + 0.005, name);
  }
  dir.write("rgb.txt", rgb);
  dir.write("depth.txt", depth);
}

template <typename Fn>
std::string error_of(Fn&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

// Captures spdlog messages for the lifetime of the object.
class LogCapture {
 public:
  LogCapture() : sink_(std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(100)), old_(spdlog::default_logger()) {
    spdlog::set_default_logger(std::make_shared<spdlog::logger>("capture", sink_));
  }
  ~LogCapture() { spdlog::set_default_logger(old_); }
  std::string text() const {
    std::string all;
    for (const auto& line : sink_->last_formatted()) all += line;
    return all;
  }

 private:
  std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> sink_;
  std::shared_ptr<spdlog::logger> old_;
};

// ---- lists and association ----

std::vector<ListEntry> entries(std::initializer_list<double> stamps) {
  std::vector<ListEntry> out;
  for (double t : stamps) out.push_back({t, fmt::format("{}", t), ""});
  return out;
}

TEST(FrameList, AssociatesNearestWithinToleranceOneToOne) {
  const auto pairs = associate_frames(entries({1.0, 1.1, 1.2, 1.3}), entries({1.005, 1.095, 1.115, 1.25}));
  ASSERT_EQ(pairs.size(), 2u);  // 1.2 and 1.3 have no depth within 0.02 s
  EXPECT_DOUBLE_EQ(pairs[0].rgb.timestamp, 1.0);
  EXPECT_DOUBLE_EQ(pairs[0].depth.timestamp, 1.005);
  EXPECT_DOUBLE_EQ(pairs[1].rgb.timestamp, 1.1);
  EXPECT_DOUBLE_EQ(pairs[1].depth.timestamp, 1.095);  // nearer than 1.115
}

TEST(FrameList, GreedyBySmallestDifferenceUsesEachDepthOnce) {
  // Both rgb stamps are nearest to depth 1.008; the closer pair (1.010, dt 0.002) takes it and 1.000 pairs
  // with what is left within tolerance (1.015, dt 0.015).
  const auto pairs = associate_frames(entries({1.000, 1.010}), entries({1.008, 1.015}));
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_DOUBLE_EQ(pairs[0].rgb.timestamp, 1.000);
  EXPECT_DOUBLE_EQ(pairs[0].depth.timestamp, 1.015);
  EXPECT_DOUBLE_EQ(pairs[1].rgb.timestamp, 1.010);
  EXPECT_DOUBLE_EQ(pairs[1].depth.timestamp, 1.008);
  const auto single = associate_frames(entries({1.000, 1.010}), entries({1.008}));
  ASSERT_EQ(single.size(), 1u);
  EXPECT_DOUBLE_EQ(single[0].rgb.timestamp, 1.010);
}

TEST(FrameList, LargeStampsStillPairWithinTolerance) {
  // At 1e15 s a double's step is 0.125 s, so t + 0.02 == t: the window must be tested on differences.
  const auto pairs = associate_frames(entries({1e15, 1e15 + 1}), entries({1e15, 1e15 + 1}));
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[1].depth.timestamp, 1e15 + 1);
}

TEST(FrameList, ListErrorsNameFileAndLine) {
  TempDir dir;
  struct Case {
    std::string line, expect;
  };
  for (const Case& c : {Case{"2.0", "expected 'timestamp path'"}, Case{"2.0 a.png extra", "expected"},
                        Case{"x2 a.png", "expected"}, Case{"nan a.png", "not a finite"},
                        Case{"inf a.png", "not a finite"}, Case{"1.0 b.png", "not after"},
                        Case{"0.5 b.png", "not after"}}) {
    const auto file = dir.write("rgb.txt", "# header\n1.0 a.png\n" + c.line + "\n");
    EXPECT_THAT(error_of([&] { read_frame_list(file); }),
                AllOf(HasSubstr(file.string() + ":3:"), HasSubstr(c.expect)))
        << c.line;
  }
  const auto assoc = dir.write("associations.txt", "1.0 a.png 1.0 b.png\n2.0 a.png 2.0\n");
  EXPECT_THAT(error_of([&] { read_associations(assoc); }), HasSubstr(assoc.string() + ":2:"));
}

// ---- depth ----

TEST(DepthImage, ScalesByFactorAndDropsNoDepthMarkers) {
  cv::Mat raw(2, 3, CV_16UC1);
  raw.at<std::uint16_t>(0, 0) = 5000;
  raw.at<std::uint16_t>(0, 1) = 0;
  raw.at<std::uint16_t>(0, 2) = 65535;
  raw.at<std::uint16_t>(1, 0) = 1;
  raw.at<std::uint16_t>(1, 1) = 65534;
  raw.at<std::uint16_t>(1, 2) = 2500;
  const cv::Mat m = depth_to_metres(raw, 5000.0);
  ASSERT_EQ(m.type(), CV_32FC1);
  EXPECT_FLOAT_EQ(m.at<float>(0, 0), 1.0f);
  EXPECT_FLOAT_EQ(m.at<float>(0, 1), 0.0f);
  EXPECT_FLOAT_EQ(m.at<float>(0, 2), 0.0f);
  EXPECT_FLOAT_EQ(m.at<float>(1, 0), 0.0002f);
  EXPECT_NEAR(m.at<float>(1, 1), 13.1068f, 1e-4);
  EXPECT_FLOAT_EQ(m.at<float>(1, 2), 0.5f);
  EXPECT_FLOAT_EQ(depth_to_metres(raw, 1000.0).at<float>(0, 0), 5.0f);
  EXPECT_NEAR(median_valid_depth(m, 1), 1.0, 1e-6);  // sorted {0.0002, 0.5, 1, 13.1}: upper median
}

// ---- datasets ----

TEST(Dataset, TumFolderLoadsFramesInOrderWithMetricDepth) {
  TempDir dir;
  make_tum(dir, 3, 10000);
  dir.write("groundtruth.txt", "100.0 0 0 0 0 0 0 1\n");
  const auto ds = open_dataset(dir.path(), tiny_settings(5000.0));
  EXPECT_EQ(ds->layout(), "tum");
  EXPECT_EQ(ds->root(), dir.path());
  ASSERT_EQ(ds->size(), 3u);
  ASSERT_TRUE(ds->groundtruth().has_value());
  EXPECT_EQ(*ds->groundtruth(), dir / "groundtruth.txt");
  EXPECT_NEAR(ds->timestamp(1), 100.0 + 1 / 30.0, 1e-6);

  const RgbdFrame f = ds->load(2);
  EXPECT_EQ(f.index, 2u);
  EXPECT_NEAR(f.timestamp, 100.0 + 2 / 30.0, 1e-6);
  ASSERT_EQ(f.bgr.type(), CV_8UC3);
  ASSERT_EQ(f.gray.type(), CV_8UC1);
  ASSERT_EQ(f.depth.type(), CV_32FC1);
  EXPECT_EQ(f.bgr.size(), cv::Size(kW, kH));
  EXPECT_EQ(f.bgr.at<cv::Vec3b>(5, 5), cv::Vec3b(10, 200, 50));
  EXPECT_NEAR(f.gray.at<std::uint8_t>(5, 5), 0.299 * 50 + 0.587 * 200 + 0.114 * 10, 1.0);
  EXPECT_FLOAT_EQ(f.depth.at<float>(5, 5), 2.0f);  // 10000 / 5000
  EXPECT_FLOAT_EQ(f.depth.at<float>(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(f.depth.at<float>(0, 1), 0.0f);  // 65535 is "no depth"
  EXPECT_THAT(f.rgb_path, HasSubstr("rgb/"));
  EXPECT_THAT(f.depth_path, HasSubstr("depth/"));
}

TEST(Dataset, DepthFactorComesFromSettings) {
  TempDir dir;
  make_tum(dir, 1, 2000);
  EXPECT_FLOAT_EQ(open_dataset(dir.path(), tiny_settings(1000.0))->load(0).depth.at<float>(3, 3), 2.0f);
  EXPECT_FLOAT_EQ(open_dataset(dir.path(), tiny_settings(5000.0))->load(0).depth.at<float>(3, 3), 0.4f);
}

TEST(Dataset, TumDropsColourWithoutDepthPartner) {
  TempDir dir;
  make_tum(dir, 4);
  // Depth list without the third frame's partner.
  dir.write("depth.txt", fmt::format("{:.6f} depth/{:.6f}.png\n{:.6f} depth/{:.6f}.png\n{:.6f} depth/{:.6f}.png\n",
                                     100.005, 100.0, 100.0 + 1 / 30.0 + 0.005, 100.0 + 1 / 30.0,
                                     100.0 + 3 / 30.0 + 0.005, 100.0 + 3 / 30.0));
  const auto ds = open_dataset(dir.path(), tiny_settings());
  ASSERT_EQ(ds->size(), 3u);
  EXPECT_NEAR(ds->timestamp(2), 100.0 + 3 / 30.0, 1e-6);
  EXPECT_FALSE(ds->groundtruth().has_value());
}

TEST(Dataset, AssociationsFileIsUsedAsIs) {
  TempDir dir;
  write_rgb(dir / "rgb/a.png");
  write_rgb(dir / "rgb/b.png");
  write_depth(dir / "depth/x.png", 5000);
  write_depth(dir / "depth/y.png", 15000);
  // Depth stamps 0.5 s off: association by time would reject them, the file's pairing is trusted.
  dir.write("associations.txt", "1.0 rgb/a.png 1.5 depth/y.png\n2.0 rgb/b.png 2.5 depth/x.png\n");
  const auto ds = open_dataset(dir.path(), tiny_settings());
  ASSERT_EQ(ds->size(), 2u);
  EXPECT_FLOAT_EQ(ds->load(0).depth.at<float>(4, 4), 3.0f);
  EXPECT_FLOAT_EQ(ds->load(1).depth.at<float>(4, 4), 1.0f);
}

TEST(Dataset, OpenLorisLayoutIsDetectedByItsListFiles) {
  TempDir dir;
  write_rgb(dir / "color/1.png");
  write_depth(dir / "aligned_depth/1.png", 1500);
  dir.write("color.txt", "1560000000.100 color/1.png\n");
  dir.write("aligned_depth.txt", "1560000000.101 aligned_depth/1.png\n");
  dir.write("groundtruth.txt", "1560000000.1 0 0 0 0 0 0 1\n");
  const auto ds = open_dataset(dir.path(), tiny_settings(1000.0));
  EXPECT_EQ(ds->layout(), "openloris");
  ASSERT_EQ(ds->size(), 1u);
  EXPECT_TRUE(ds->groundtruth().has_value());
  EXPECT_FLOAT_EQ(ds->load(0).depth.at<float>(2, 2), 1.5f);
  // Without settings, an OpenLORIS folder gets its depth factor.
  EXPECT_DOUBLE_EQ(settings_for_dataset(dir.path(), std::nullopt).depth_factor, 1000.0);
}

TEST(Dataset, FolderAndListErrors) {
  TempDir dir;
  EXPECT_THAT(error_of([&] { open_dataset(dir / "nope", tiny_settings()); }),
              AllOf(HasSubstr("nope"), HasSubstr("does not exist")));
  const auto file = dir.write("file.txt", "x");
  EXPECT_THAT(error_of([&] { open_dataset(file, tiny_settings()); }), HasSubstr("not a folder"));
  EXPECT_THAT(error_of([&] { open_dataset(dir.path(), tiny_settings()); }), HasSubstr("rgb.txt"));

  make_tum(dir, 2);
  fs::remove(dir / "depth.txt");
  EXPECT_THAT(error_of([&] { open_dataset(dir.path(), tiny_settings()); }),
              AllOf(HasSubstr("missing list file"), HasSubstr("depth.txt")));

  dir.write("depth.txt", "100.005 depth/a.png\n100.005 depth/b.png\n");  // duplicate timestamp
  EXPECT_THAT(error_of([&] { open_dataset(dir.path(), tiny_settings()); }),
              AllOf(HasSubstr("depth.txt:2:"), HasSubstr("not after")));

  dir.write("depth.txt", "200 depth/a.png\n");  // nothing within 0.02 s
  EXPECT_THAT(error_of([&] { open_dataset(dir.path(), tiny_settings()); }), HasSubstr("within"));

  fs::remove(dir / "color.txt");
  dir.write("aligned_depth.txt", "1.0 d.png\n");  // OpenLORIS without its colour list
  EXPECT_THAT(error_of([&] { open_dataset(dir.path(), tiny_settings()); }),
              AllOf(HasSubstr("missing list file"), HasSubstr("color.txt")));
}

TEST(Dataset, ImageErrorsNameTheFileAndListLine) {
  TempDir dir;
  make_tum(dir, 5);
  const auto ds_files = read_frame_list(dir / "rgb.txt");
  const auto depth_files = read_frame_list(dir / "depth.txt");
  fs::remove(dir / ds_files[0].path);                                                       // missing
  std::ofstream(dir / ds_files[1].path) << "not a png";                                     // unreadable
  write_rgb(dir / ds_files[2].path, {1, 2, 3}, kW * 2, kH);                                 // wrong size
  ASSERT_TRUE(cv::imwrite((dir / depth_files[3].path).string(), cv::Mat(kH, kW, CV_8UC1, cv::Scalar(9))));
  write_depth(dir / depth_files[4].path, 100, kW, kH + 2);                                  // wrong depth size
  const auto ds = open_dataset(dir.path(), tiny_settings());
  ASSERT_EQ(ds->size(), 5u);
  const std::string rgb_list = (dir / "rgb.txt").string(), depth_list = (dir / "depth.txt").string();
  EXPECT_THAT(error_of([&] { ds->load(0); }),
              AllOf(HasSubstr(rgb_list + ":3:"), HasSubstr(ds_files[0].path), HasSubstr("does not exist")));
  EXPECT_THAT(error_of([&] { ds->load(1); }),
              AllOf(HasSubstr(rgb_list + ":4:"), HasSubstr(ds_files[1].path), HasSubstr("is not a PNG or JPEG image")));
  EXPECT_THAT(error_of([&] { ds->load(2); }),
              AllOf(HasSubstr(ds_files[2].path), HasSubstr("64x24"), HasSubstr("32x24")));
  EXPECT_THAT(error_of([&] { ds->load(3); }),
              AllOf(HasSubstr(depth_list + ":5:"), HasSubstr("8-bit"), HasSubstr("16-bit")));
  EXPECT_THAT(error_of([&] { ds->load(4); }), AllOf(HasSubstr(depth_files[4].path), HasSubstr("32x26")));
}

TEST(Dataset, ImplausibleMedianDepthWarnsOnceWithTheNumbers) {
  TempDir dir;
  make_tum(dir, 3, 30000);  // 30 m at factor 1000: as if a TUM file were read with the 7-Scenes factor
  LogCapture log;
  const auto ds = open_dataset(dir.path(), tiny_settings(1000.0));
  for (std::size_t i = 0; i < ds->size(); ++i) EXPECT_NO_THROW(ds->load(i));
  const std::string text = log.text();
  EXPECT_THAT(text, AllOf(HasSubstr("median valid depth is 30.000 m"), HasSubstr("depth factor 1000")));
  EXPECT_EQ(text.find("median valid depth"), text.rfind("median valid depth"));  // once

  TempDir ok;
  make_tum(ok, 1, 10000);
  LogCapture quiet;
  open_dataset(ok.path(), tiny_settings(5000.0))->load(0);
  EXPECT_THAT(quiet.text(), ::testing::Not(HasSubstr("median valid depth")));
}

TEST(Dataset, SettingsForDatasetPrefersExplicitThenFolderThenDefaults) {
  TempDir dir;
  make_tum(dir, 1);
  const Settings defaults = settings_for_dataset(dir.path(), std::nullopt);
  EXPECT_TRUE(defaults.source.empty());
  EXPECT_DOUBLE_EQ(defaults.camera.fx, 517.3);

  Settings folder = tiny_settings(1000.0);
  folder.camera.fx = 600;
  save_settings(folder, dir / "settings.yaml");
  EXPECT_DOUBLE_EQ(settings_for_dataset(dir.path(), std::nullopt).camera.fx, 600);

  Settings other = tiny_settings();
  other.camera.fx = 700;
  save_settings(other, dir / "other.yaml");
  EXPECT_DOUBLE_EQ(settings_for_dataset(dir.path(), dir / "other.yaml").camera.fx, 700);
  EXPECT_THROW(settings_for_dataset(dir.path(), dir / "missing.yaml"), ConfigError);

  // A settings.yaml that is there but cannot be read is an error, not the default camera.
  std::filesystem::remove(dir / "settings.yaml");
  std::filesystem::create_symlink(dir / "moved.yaml", dir / "settings.yaml");
  EXPECT_THROW(settings_for_dataset(dir.path(), std::nullopt), ConfigError);
}

// ---- prefetcher ----

TEST(FramePrefetcher, DeliversEveryFrameInOrder) {
  TempDir dir;
  make_tum(dir, 12);
  const auto ds = open_dataset(dir.path(), tiny_settings());
  FramePrefetcher pf(*ds, 2);
  std::size_t expected = 0;
  while (auto f = pf.next()) {
    EXPECT_EQ(f->index, expected);
    EXPECT_DOUBLE_EQ(f->timestamp, ds->timestamp(expected));
    EXPECT_FALSE(f->depth.empty());
    ++expected;
  }
  EXPECT_EQ(expected, 12u);
  EXPECT_EQ(pf.skipped(), 0u);
  EXPECT_FALSE(pf.next().has_value());  // stays at the end
}

TEST(FramePrefetcher, PreparesEveryFrameBeforeHandingItOver) {
  TempDir dir;
  make_tum(dir, 5);
  const auto ds = open_dataset(dir.path(), tiny_settings());
  FramePrefetcher pf(*ds, 2, 0, SIZE_MAX, [](RgbdFrame& f) { f.depth.setTo(1.25f); });
  std::size_t n = 0;
  while (auto f = pf.next()) {
    double lo = 0, hi = 0;
    cv::minMaxLoc(f->depth, &lo, &hi);
    EXPECT_FLOAT_EQ(static_cast<float>(lo), 1.25f);
    EXPECT_FLOAT_EQ(static_cast<float>(hi), 1.25f);
    ++n;
  }
  EXPECT_EQ(n, 5u);
}

TEST(FramePrefetcher, HonoursFirstAndCount) {
  TempDir dir;
  make_tum(dir, 10);
  const auto ds = open_dataset(dir.path(), tiny_settings());
  std::vector<std::size_t> got;
  {
    FramePrefetcher pf(*ds, 4, 3, 4);
    while (auto f = pf.next()) got.push_back(f->index);
  }
  EXPECT_EQ(got, (std::vector<std::size_t>{3, 4, 5, 6}));
  FramePrefetcher past_end(*ds, 4, 8, 100);
  EXPECT_EQ(past_end.next()->index, 8u);
  EXPECT_EQ(past_end.next()->index, 9u);
  EXPECT_FALSE(past_end.next().has_value());
  FramePrefetcher none(*ds, 4, 50);
  EXPECT_FALSE(none.next().has_value());
}

TEST(FramePrefetcher, SkipsUnreadableFramesAndCountsThem) {
  TempDir dir;
  make_tum(dir, 15);
  const auto rgb = read_frame_list(dir / "rgb.txt");
  fs::remove(dir / rgb[4].path);
  std::ofstream(dir / rgb[9].path) << "garbage";
  const auto ds = open_dataset(dir.path(), tiny_settings());
  FramePrefetcher pf(*ds);
  std::vector<std::size_t> got;
  while (auto f = pf.next()) got.push_back(f->index);
  EXPECT_EQ(got, (std::vector<std::size_t>{0, 1, 2, 3, 5, 6, 7, 8, 10, 11, 12, 13, 14}));
  EXPECT_EQ(pf.skipped(), 2u);
}

TEST(FramePrefetcher, ThrowsWhenTooManyFramesFail) {
  TempDir dir;
  make_tum(dir, 20);
  const auto rgb = read_frame_list(dir / "rgb.txt");
  for (std::size_t i = 5; i < 16; ++i) fs::remove(dir / rgb[i].path);  // 11 > max(10, 2)
  const auto ds = open_dataset(dir.path(), tiny_settings());
  FramePrefetcher pf(*ds);
  std::vector<std::size_t> got;
  const std::string msg = error_of([&] {
    while (auto f = pf.next()) got.push_back(f->index);
  });
  EXPECT_THAT(msg, AllOf(HasSubstr(dir.path().string()), HasSubstr("11 of 20")));
  EXPECT_EQ(got, (std::vector<std::size_t>{0, 1, 2, 3, 4}));  // good frames before the failure still arrive

  // Ten failures are tolerated (the limit is "more than max(10, 10%)").
  write_rgb(dir / rgb[5].path);
  FramePrefetcher tolerant(*ds);
  std::size_t n = 0;
  while (tolerant.next()) ++n;
  EXPECT_EQ(n, 10u);
  EXPECT_EQ(tolerant.skipped(), 10u);
}

TEST(FramePrefetcher, DestroyingMidwayStopsTheWorker) {
  TempDir dir;
  make_tum(dir, 20);
  const auto ds = open_dataset(dir.path(), tiny_settings());
  FramePrefetcher pf(*ds, 1);
  ASSERT_TRUE(pf.next().has_value());
  // Leaving scope joins the worker, which is blocked on a full queue: must not hang.
}

// ---- real data ----

TEST(Dataset, Reads7ScenesRedkitchenAsIs) {
  const fs::path dir = fs::path(VARSLAM_SHARED_DIR) / "realdata/7scenes_redkitchen";
  if (!fs::exists(dir)) GTEST_SKIP() << "shared data not present: " << dir;
  const Settings s = settings_for_dataset(dir, std::nullopt);
  EXPECT_DOUBLE_EQ(s.depth_factor, 1000.0);
  const auto ds = open_dataset(dir, s);
  EXPECT_EQ(ds->layout(), "tum");
  EXPECT_EQ(ds->size(), 1000u);
  EXPECT_TRUE(ds->groundtruth().has_value());
  LogCapture log;
  FramePrefetcher pf(*ds, 2, 0, 3);
  std::size_t n = 0;
  while (auto f = pf.next()) {
    EXPECT_EQ(f->index, n);
    EXPECT_EQ(f->bgr.size(), cv::Size(640, 480));
    EXPECT_EQ(f->gray.type(), CV_8UC1);
    double lo = 0, hi = 0;
    cv::minMaxLoc(f->depth, &lo, &hi);
    EXPECT_GE(lo, 0.0);
    EXPECT_LT(hi, 10.0);  // 65535 markers must not become 65 m points
    const double median = median_valid_depth(f->depth);
    EXPECT_GT(median, 0.3);
    EXPECT_LT(median, 5.0);
    ++n;
  }
  EXPECT_EQ(n, 3u);
  EXPECT_EQ(pf.skipped(), 0u);
  EXPECT_THAT(log.text(), ::testing::Not(HasSubstr("median valid depth")));
}

}  // namespace
}  // namespace varslam
