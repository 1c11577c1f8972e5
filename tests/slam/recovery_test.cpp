// Tracking loss and its recovery on remixed sequences: a camera covered for a while (black frames), and a camera
// carried back to where the run started ("kidnapped"), where only global relocalization or loop closing can put
// the new frames back into the old map.
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "e2e_support.hpp"

namespace varslam::slam {
namespace {

namespace fs = std::filesystem;
using run::RunOptions;
using run::RunSummary;
using run::run_slam;

struct ListEntry {
  std::string stamp, rest;
};

std::vector<ListEntry> read_list(const fs::path& file) {
  std::vector<ListEntry> out;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto sp = line.find(' ');
    out.push_back({line.substr(0, sp), line.substr(sp + 1)});
  }
  return out;
}

constexpr int kBlack = -1;  // frame index standing for a black frame (a covered lens)

/// Writes a TUM-layout sequence playing `src`'s frames in the order `frames` (kBlack: black colour, no depth) at
/// 30 Hz, with image paths pointing into `src` and the ground truth of each original frame.
fs::path remix(const fs::path& src, const std::string& name, const std::vector<int>& frames) {
  const fs::path dst = fs::temp_directory_path() / ("varslam_recovery_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dst);
  fs::create_directories(dst);
  fs::copy_file(src / "settings.yaml", dst / "settings.yaml");
  const auto rgb = read_list(src / "rgb.txt"), depth = read_list(src / "depth.txt");
  std::map<std::string, std::string> gt;
  for (const auto& e : read_list(src / "groundtruth.txt")) gt[e.stamp] = e.rest;
  const cv::Mat probe = cv::imread((src / rgb.front().rest).string(), cv::IMREAD_UNCHANGED);
  cv::imwrite((dst / "black.png").string(), cv::Mat::zeros(probe.size(), CV_8UC3));
  cv::imwrite((dst / "nodepth.png").string(), cv::Mat::zeros(probe.size(), CV_16UC1));
  std::ofstream r(dst / "rgb.txt"), d(dst / "depth.txt"), g(dst / "groundtruth.txt");
  const double t0 = std::stod(rgb.front().stamp);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const std::string t = std::to_string(t0 + static_cast<double>(k) / 30.0);
    const int i = frames[k];
    if (i == kBlack) {
      r << t << " " << (dst / "black.png").string() << "\n";
      d << t << " " << (dst / "nodepth.png").string() << "\n";
      continue;
    }
    r << t << " " << (src / rgb[static_cast<std::size_t>(i)].rest).string() << "\n";
    d << t << " " << (src / depth[static_cast<std::size_t>(i)].rest).string() << "\n";
    const auto it = gt.find(rgb[static_cast<std::size_t>(i)].stamp);
    if (it != gt.end()) g << t << " " << it->second << "\n";
  }
  return dst;
}

std::vector<int> range(int from, int to) {
  std::vector<int> v;
  for (int i = from; i < to; ++i) v.push_back(i);
  return v;
}

std::vector<int> operator+(std::vector<int> a, const std::vector<int>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

RunSummary run_named(const fs::path& data, const std::string& name,
                     const std::vector<std::string>& overrides = {}) {
  const fs::path out = fs::temp_directory_path() / ("varslam_recovery_out_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(out);
  return e2e::run_on(data, out, RunMode::Deterministic, SIZE_MAX, overrides);
}

fs::path recovery_sequence() {
  synth::SynthConfig cfg;
  cfg.scenario = "static";
  cfg.seconds = 4.0;
  cfg.seed = 11;
  return e2e::cached_sequence("recovery_static", cfg);
}

// A covered lens for a third of a second while the camera moves on: tracking is lost (black frames have no
// keypoints), then recovered in the same map, not in a new segment.
TEST(Recovery, CoveredLensIsRecoveredInTheSameMap) {
  const fs::path seq = remix(recovery_sequence(), "covered", range(0, 60) + std::vector<int>(10, kBlack) + range(70, 120));
  const RunSummary s = run_named(seq, "covered");
  EXPECT_EQ(s.segments, 1);
  EXPECT_EQ(s.lost, 10u);
  ASSERT_TRUE(s.ate_rmse.has_value());
  EXPECT_LT(*s.ate_rmse, 0.02) << "ATE RMSE " << *s.ate_rmse << " m";
}

// The real kitchen: the camera is carried from the far end of the room (frame 520) back to where the run began.
// Local recovery cannot place the first frames again; without relocalization and loop closing a new map segment
// starts at a wrong pose (measured: ATE 15.3 cm, max 66 cm, against 3.4 / 3.6 cm with either of them). Not every
// jump needs them: with depth registered to colour, from frame 560 the reference keyframe's neighbourhood
// recovers the pose on its own. Relocalization finds keyframe 0 by its place signature and locates the frame by
// RANSAC; with relocalization off, loop closing merges the new segment into the old map instead.
class KidnappedInKitchen : public ::testing::Test {
 protected:
  void SetUp() override {
    const fs::path data = fs::path(VARSLAM_SHARED_DIR) / "realdata" / "7scenes_redkitchen";
    if (!fs::exists(data)) GTEST_SKIP() << "real data not found at " << data << " (../shared is absent)";
    seq_ = remix(data, "kitchen520", range(0, 520) + range(0, 30));
  }
  fs::path seq_;
};

TEST_F(KidnappedInKitchen, RelocalizationPutsTheCameraBackIntoTheMap) {
  const RunSummary s = run_named(seq_, "kitchen_reloc");
  EXPECT_EQ(s.segments, 1);
  EXPECT_GE(s.metrics.at("relocalizations").get<int>(), 1);
  EXPECT_LE(s.lost, 3u);
  ASSERT_TRUE(s.ate_rmse.has_value());
  EXPECT_LT(*s.ate_rmse, 0.05) << "ATE RMSE " << *s.ate_rmse << " m";
}

TEST_F(KidnappedInKitchen, LoopClosingMergesTheNewSegmentIntoTheOldMap) {
  const RunSummary s = run_named(seq_, "kitchen_loop", {"relocalization.enabled=false"});
  EXPECT_EQ(s.segments, 2);
  ASSERT_GE(s.metrics.at("loops").size(), 1u);
  EXPECT_EQ(s.metrics.at("loops")[0].at("loop_keyframe").get<long>(), 0);
  ASSERT_TRUE(s.ate_rmse.has_value());
  EXPECT_LT(*s.ate_rmse, 0.05) << "ATE RMSE " << *s.ate_rmse << " m";
}

}  // namespace
}  // namespace varslam::slam
