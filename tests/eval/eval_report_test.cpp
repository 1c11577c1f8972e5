// The report layer: table, JSON and plot files built from one evaluation.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "eval/eval_report.hpp"
#include "eval_test_util.hpp"

namespace varslam {
namespace {

// A loop in the x-z plane (y nearly constant) observed 10 % too large, at 30 Hz, ground truth at 100 Hz.
void loop(Trajectory& gt, Trajectory& est) {
  for (int k = 0; k <= 1000; ++k) {
    const double t = 0.01 * k;
    gt.push_back({t, test::pose({std::cos(0.6 * t), 0.01 * std::sin(t), std::sin(0.6 * t)}, {0, 0.6 * t, 0})});
  }
  for (int k = 0; k <= 300; ++k) {
    const double t = k / 30.0;
    est.push_back({t + 0.001, test::pose({1.1 * std::cos(0.6 * t), 0.0, 1.1 * std::sin(0.6 * t)}, {0, 0.6 * t, 0})});
  }
}

TEST(EvalReport, SummaryJsonAndTableAgree) {
  Trajectory gt, est;
  loop(gt, est);
  EvalOptions opt;
  opt.frame_count = 400;
  const EvalSummary s = evaluate_trajectory(gt, est, opt);
  EXPECT_EQ(s.ate.stats.count, 301u);
  EXPECT_NEAR(s.ate.stats.mean, 0.1, 0.005);  // radial 10 % of a unit circle
  ASSERT_TRUE(s.rpe.has_value());
  EXPECT_DOUBLE_EQ(s.correct_rate, 301.0 / 400.0);

  const nlohmann::json j = eval_to_json(s, true);
  EXPECT_DOUBLE_EQ(j["ate"]["rmse"].get<double>(), s.ate.stats.rmse);
  EXPECT_EQ(j["ate"]["pairs"].get<std::size_t>(), 301u);
  for (const char* k : {"mean", "median", "std", "min", "max"}) EXPECT_TRUE(j["ate"].contains(k)) << k;
  EXPECT_DOUBLE_EQ(j["rpe"]["translation_m"]["rmse"].get<double>(), s.rpe->translation.rmse);
  EXPECT_DOUBLE_EQ(j["rpe"]["rotation_deg"]["max"].get<double>(), s.rpe->rotation_deg.max);
  EXPECT_DOUBLE_EQ(j["correct_rate"].get<double>(), 0.7525);
  EXPECT_EQ(j["ate_per_pair"]["error_m"].size(), 301u);
  EXPECT_FALSE(eval_to_json(s, false).contains("ate_per_pair"));

  const std::string table = format_eval_table(s);
  char rmse[32];
  std::snprintf(rmse, sizeof rmse, "%.6f", s.ate.stats.rmse);
  EXPECT_NE(table.find(rmse), std::string::npos) << table;
  EXPECT_NE(table.find("RPE trans"), std::string::npos);
  EXPECT_NE(table.find("75.25 %"), std::string::npos) << table;
}

TEST(EvalReport, CorrectRateDefaultsToEstimatePoses) {
  Trajectory gt, est;
  loop(gt, est);
  est.push_back({50.0, Eigen::Isometry3d::Identity()});  // beyond the ground truth: no pair
  const EvalSummary s = evaluate_trajectory(gt, est);
  EXPECT_EQ(s.frame_count, 302u);
  EXPECT_FALSE(s.frame_count_given);
  EXPECT_DOUBLE_EQ(s.correct_rate, 301.0 / 302.0);
}

TEST(EvalReport, TopViewUsesTheTwoAxesOfMostSpread) {
  Trajectory gt, est;
  loop(gt, est);
  EXPECT_EQ(top_view_axes(gt), std::make_pair(0, 2));  // the loop lies in x-z
  const Plot p = trajectory_top_view_plot(gt, evaluate_ate(gt, est));
  EXPECT_EQ(p.options().x_label, "x [m]");
  EXPECT_EQ(p.options().y_label, "z [m]");
  EXPECT_TRUE(p.options().equal_aspect);
  ASSERT_GE(p.series().size(), 2u);
  EXPECT_EQ(p.series()[0].x.size(), gt.size());
  EXPECT_EQ(p.series()[1].x.size(), est.size());
}

TEST(EvalReport, WritesBothPlots) {
  Trajectory gt, est;
  loop(gt, est);
  const EvalSummary s = evaluate_trajectory(gt, est);
  const auto dir = std::filesystem::path(VARSLAM_BINARY_DIR) / "test_eval_out";
  std::filesystem::create_directories(dir);
  const auto files = write_eval_plots(gt, s, dir / "report.svg");
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[1].filename(), "report_ate_error.svg");
  for (const auto& f : files) {
    std::ifstream in(f);
    std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(content.find("</svg>"), std::string::npos) << f;
    EXPECT_NE(content.find("<polyline"), std::string::npos) << f;
  }
}

}  // namespace
}  // namespace varslam
