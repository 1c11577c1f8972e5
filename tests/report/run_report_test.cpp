#include "report/run_report.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "core/error.hpp"
#include "io/trajectory_io.hpp"
#include "report/html_check.hpp"

namespace varslam::report {
namespace {
namespace fs = std::filesystem;

// A small run folder and sequence folder, written the way `varslam run` and `varslam synth` write them.
class RunReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("varslam_run_report_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(root_);
    run_ = root_ / "run";
    seq_ = root_ / "seq";
    fs::create_directories(run_);
    fs::create_directories(seq_);
    Trajectory gt, est;
    for (int i = 0; i < 60; ++i) {
      StampedPose p;
      p.timestamp = 100.0 + i / 30.0;
      p.T_wc.translation() = Eigen::Vector3d(0.02 * i, 0.3 * std::sin(0.1 * i), 1.0);
      gt.push_back(p);
      p.T_wc.translation().x() += 0.01 * std::sin(0.5 * i);  // some error to plot
      est.push_back(p);
    }
    write_tum_trajectory(gt, seq_ / "groundtruth.txt");
    write_tum_trajectory(est, run_ / "CameraTrajectory.txt");
    cv::imwrite((seq_ / "preview.png").string(), cv::Mat(120, 160, CV_8UC3, cv::Scalar(40, 90, 200)));
    metrics_ = {{"dataset", seq_.string()},
                {"mode", "deterministic"},
                {"frames", 60},
                {"tracked_frames", 58},
                {"lost_frames", 2},
                {"map_segments", 1},
                {"keyframes", 7},
                {"map_points", 1234},
                {"fps", 17.5},
                {"wall_seconds", 3.43},
                {"kernels", {{"tracking", "barron-fixed"}, {"mapping", "barron-adaptive"}}},
                {"ate", {{"rmse", 0.01234}, {"mean", 0.011}, {"median", 0.01}, {"max", 0.0456}, {"pairs", 58},
                         {"correct_rate", 0.9667}}},
                {"rpe", {{"trans_rmse", 0.02}, {"rot_rmse_deg", 0.5}}},
                {"timings", {{"extract", {{"median_ms", 12.5}, {"p95_ms", 20.0}, {"count", 60}}},
                             {"tracking", {{"median_ms", 31.25}, {"p95_ms", 47.0}, {"count", 60}}},
                             {"local_ba", {{"median_ms", 150.0}, {"p95_ms", 300.0}, {"count", 6}}}}},
                {"local_ba", nlohmann::json::array()}};
    for (int k = 0; k < 6; ++k)
      metrics_["local_ba"].push_back({{"keyframe", k}, {"timestamp", 100.0 + 0.3 * k}, {"final_alpha", 0.5 + 0.1 * k}});
  }
  void TearDown() override { fs::remove_all(root_); }
  void write_metrics() { std::ofstream(run_ / "metrics.json") << metrics_.dump(2); }

  fs::path root_, run_, seq_;
  nlohmann::json metrics_;
};

TEST_F(RunReportTest, WellFormedWithEveryPlotTheNumbersAndThePreview) {
  write_metrics();
  write_run_report(run_, seq_, run_ / "report.html");
  std::ifstream in(run_ / "report.html");
  const std::string html{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_EQ(testing::html_tag_balance_problem(html), "");
  EXPECT_EQ(html.find("<?xml"), std::string::npos) << "inline SVG must not carry an XML prolog";
  for (const char* id : {"key-numbers", "plot-trajectory", "plot-ate-error", "plot-alpha", "plot-timing", "preview"})
    EXPECT_NE(html.find(std::string("id=\"") + id + "\""), std::string::npos) << id;
  // Key numbers in the units people read.
  EXPECT_NE(html.find("1.23 cm"), std::string::npos);   // ATE RMSE
  EXPECT_NE(html.find("4.56 cm"), std::string::npos);   // ATE max
  EXPECT_NE(html.find("96.7 %"), std::string::npos);    // correct rate
  EXPECT_NE(html.find("17.5"), std::string::npos);      // fps
  EXPECT_NE(html.find("31.2 / 47.0 ms"), std::string::npos);  // tracking median / p95
  EXPECT_NE(html.find("barron-adaptive"), std::string::npos);
  EXPECT_NE(html.find("data:image/jpeg;base64,"), std::string::npos);
  EXPECT_NE(html.find("final alpha"), std::string::npos);
  // Four inline plots, each an SVG element.
  std::size_t svgs = 0;
  for (auto p = html.find("<svg"); p != std::string::npos; p = html.find("<svg", p + 1)) ++svgs;
  EXPECT_EQ(svgs, 4u);
}

TEST_F(RunReportTest, SequenceDefaultsToTheDatasetInTheMetrics) {
  write_metrics();
  const RunReportInputs in = load_run_report_inputs(run_);
  EXPECT_EQ(in.sequence_dir, seq_);
  EXPECT_EQ(in.groundtruth.size(), 60u);
  EXPECT_EQ(in.estimate.size(), 60u);
  EXPECT_TRUE(in.preview_uri.has_value());
}

TEST_F(RunReportTest, HuberRunSaysThereIsNoAlpha) {
  for (auto& ba : metrics_["local_ba"]) ba["final_alpha"] = nullptr;
  metrics_["kernels"]["mapping"] = "huber";
  write_metrics();
  const std::string html = render_run_report(load_run_report_inputs(run_, seq_));
  EXPECT_NE(html.find("id=\"no-alpha\""), std::string::npos);
  EXPECT_EQ(html.find("id=\"plot-alpha\""), std::string::npos);
  EXPECT_EQ(testing::html_tag_balance_problem(html), "");
}

TEST_F(RunReportTest, LostRunWithoutTrajectoryStillReports) {
  metrics_.erase("ate");
  write_metrics();
  fs::remove(run_ / "CameraTrajectory.txt");
  const std::string html = render_run_report(load_run_report_inputs(run_, seq_));
  EXPECT_EQ(testing::html_tag_balance_problem(html), "");
  EXPECT_EQ(html.find("id=\"plot-trajectory\""), std::string::npos);
  EXPECT_NE(html.find("n/a"), std::string::npos);
}

TEST_F(RunReportTest, MissingMetricsIsAnInputErrorNamingTheFile) {
  try {
    write_run_report(run_, seq_, run_ / "report.html");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("metrics.json"), std::string::npos);
  }
}

TEST(AlphaPlot, UsesFinalAlphaAgainstTimeSinceT0) {
  nlohmann::json m = {{"local_ba", {{{"timestamp", 10.5}, {"final_alpha", 1.25}}, {{"timestamp", 11.0}, {"final_alpha", 0.75}}}}};
  const Plot p = alpha_per_keyframe_plot(m, 10.0);
  ASSERT_FALSE(p.series().empty());
  const PlotSeries* line = nullptr;
  for (const auto& s : p.series())
    if (s.label == "final alpha") line = &s;
  ASSERT_NE(line, nullptr);
  EXPECT_EQ(line->x, (std::vector<double>{0.5, 1.0}));
  EXPECT_EQ(line->y, (std::vector<double>{1.25, 0.75}));
}

// With the Local BA alpha capped, the fit itself is drawn too: it is what moves while a mover is in view.
TEST(AlphaPlot, DrawsTheFitBeforeTheCapOnlyWhenItDiffers) {
  const auto labels = [](const Plot& p) {
    std::vector<std::string> out;
    for (const auto& s : p.series()) out.push_back(s.label);
    return out;
  };
  nlohmann::json m = {{"local_ba", {{{"timestamp", 10.5}, {"final_alpha", 1.0}, {"fitted_alpha", 1.6}},
                                    {{"timestamp", 11.0}, {"final_alpha", 0.75}, {"fitted_alpha", 0.75}}}}};
  const Plot capped = alpha_per_keyframe_plot(m, 10.0);
  const PlotSeries* fit = nullptr;
  for (const auto& s : capped.series())
    if (s.label == "fitted alpha (before the cap)") fit = &s;
  ASSERT_NE(fit, nullptr);
  EXPECT_EQ(fit->y, (std::vector<double>{1.6, 0.75}));
  m["local_ba"][0]["fitted_alpha"] = 1.0;
  const auto uncapped = labels(alpha_per_keyframe_plot(m, 10.0));
  EXPECT_EQ(std::count(uncapped.begin(), uncapped.end(), "fitted alpha (before the cap)"), 0);
}

TEST(TimingPlot, MedianAndP95PerStageInPipelineOrder) {
  nlohmann::json m = {{"timings", {{"local_ba", {{"median_ms", 100.0}, {"p95_ms", 200.0}}},
                                   {"extract", {{"median_ms", 10.0}, {"p95_ms", 15.0}}}}}};
  const Plot p = stage_timing_plot(m);
  ASSERT_EQ(p.series().size(), 2u);
  EXPECT_EQ(p.x_categories(), (std::vector<std::string>{"extract", "local BA"}));
  EXPECT_EQ(p.series()[0].y, (std::vector<double>{10.0, 100.0}));
  EXPECT_EQ(p.series()[1].y, (std::vector<double>{15.0, 200.0}));
}

}  // namespace
}  // namespace varslam::report
