#include "report/bench_results.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "report/bench_summary.hpp"
#include "report/html_check.hpp"

namespace varslam::report {
namespace {

RunRecord rec(const std::string& scenario, const std::string& path, std::uint64_t seed, const std::string& config,
              double rmse, bool ok = true) {
  RunRecord r;
  r.sequence_id = scenario + "_" + path + "_" + std::to_string(seed);
  r.scenario = scenario;
  r.path_name = path;
  r.seed = seed;
  r.config = config;
  r.ok = ok;
  r.figures = {rmse, 2 * rmse, 0.9, 20.0, 30.0, 10.0};
  return r;
}

TEST(FiguresFromMetrics, ReadsTheRunnerKeys) {
  const nlohmann::json m = {{"ate", {{"rmse", 0.1}, {"max", 0.3}, {"correct_rate", 0.8}}},
                            {"fps", 15.0},
                            {"wall_seconds", 9.0},
                            {"timings", {{"tracking", {{"median_ms", 33.0}}}}}};
  const RunFigures f = figures_from_metrics(m);
  EXPECT_DOUBLE_EQ(f.ate_rmse_m, 0.1);
  EXPECT_DOUBLE_EQ(f.ate_max_m, 0.3);
  EXPECT_DOUBLE_EQ(f.correct_rate, 0.8);
  EXPECT_DOUBLE_EQ(f.fps, 15.0);
  EXPECT_DOUBLE_EQ(f.tracking_median_ms, 33.0);
  EXPECT_DOUBLE_EQ(f.wall_seconds, 9.0);
  EXPECT_TRUE(std::isnan(figures_from_metrics(nlohmann::json::object()).ate_rmse_m));
}

TEST(MeanOf, AveragesOnlyRunsWithTheFigure) {
  const RunRecord a = rec("w", "p", 1, "huber", 0.02), b = rec("w", "p", 2, "huber", 0.04),
                  failed = rec("w", "p", 3, "huber", 9.0, false);
  const CellMean m = mean_of({&a, &b, &failed});
  EXPECT_EQ(m.n_runs, 3u);
  EXPECT_EQ(m.n_ok, 2u);
  EXPECT_EQ(m.n_ate, 2u);
  EXPECT_NEAR(m.ate_rmse_m, 0.03, 1e-12);
  EXPECT_NEAR(m.ate_max_m, 0.06, 1e-12);
}

TEST(MarkdownTables, OneRowPerScenarioAndPerPathWithColumnGroups) {
  std::vector<RunRecord> r = {rec("walking", "pa", 1, "huber", 0.02),  rec("walking", "pa", 2, "huber", 0.04),
                              rec("walking", "pa", 1, "full", 0.01),   rec("walking", "pa", 2, "full", 0.01),
                              rec("walking", "pb", 1, "huber", 0.06),  rec("walking", "pb", 1, "full", 0.0, false),
                              rec("real", "kitchen", 0, "huber", 0.05)};
  const std::string md = render_markdown_tables(r, {{"huber", "full"}, false, "peer"});
  EXPECT_NE(md.find("| scenario | huber RMSE | huber max | huber CR % | huber fps | huber trk ms | full RMSE |"),
            std::string::npos);
  // walking over both paths: huber (2 + 4 + 6) / 3 = 4 cm; full only the two good runs of pa: 1 cm, flagged.
  EXPECT_NE(md.find("| walking | 4.00 | 8.00 | 90.0 | 20.0 | 30.0 | 1.00* | 2.00* |"), std::string::npos) << md;
  EXPECT_NE(md.find("| walking | pa | 3.00 | 6.00 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| walking | pb | 6.00 | 12.00 | 90.0 | 20.0 | 30.0 | fail | fail |"), std::string::npos) << md;
  // A real folder is its own row; its missing configuration is an empty cell.
  EXPECT_NE(md.find("| real: kitchen | 5.00 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| real: kitchen | - | 5.00 |"), std::string::npos) << md;
}

TEST(MarkdownTables, PeerColumnGroup) {
  std::vector<RunRecord> r = {rec("static", "pa", 1, "huber", 0.02), rec("static", "pa", 1, "peer", 0.03)};
  const std::string md = render_markdown_tables(r, {{"huber"}, true, "orbslam3"});
  EXPECT_NE(md.find("orbslam3 RMSE | orbslam3 max | orbslam3 s |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 3.00 | 6.00 | 10.0 |"), std::string::npos) << md;
}

// The semantic filter's target (walking within 1.5x of static along the same path) is this table's figure.
TEST(MarkdownTables, RatioToStaticPairsSeedsAlongTheSamePath) {
  std::vector<RunRecord> r = {
      rec("walking", "pa", 1, "full", 0.03), rec("walking", "pa", 2, "full", 0.03),
      rec("static", "pa", 1, "full", 0.02),  rec("static", "pa", 2, "full", 0.01),
      rec("walking", "pb", 1, "full", 0.03), rec("walking", "pb", 2, "full", 0.04),  // seed 2 has no static run
      rec("static", "pb", 1, "full", 0.01),  rec("walking", "pb", 1, "huber", 0.05),
      rec("static", "pb", 1, "huber", 0.02), rec("static", "pb", 3, "full", 0.5),  // no walking partner: unused
      rec("real", "kitchen", 0, "full", 0.05)};
  const std::string t = render_static_ratio_table(r, {"huber", "full"});
  EXPECT_NE(t.find("| scenario | path | huber | full |"), std::string::npos) << t;
  EXPECT_NE(t.find("| walking | pa |  | 2.00 |"), std::string::npos) << t;     // (3 + 3) / (2 + 1)
  EXPECT_NE(t.find("| walking | pb | 2.50 | 3.00* |"), std::string::npos) << t;  // 3 / 1, one run unpaired
  EXPECT_NE(t.find("| walking | all | 2.50 | 2.25* |"), std::string::npos) << t;  // (3 + 3 + 3) / (2 + 1 + 1)
  EXPECT_EQ(t.find("static |"), std::string::npos) << t;  // static is the reference, not a row
  EXPECT_EQ(t.find("kitchen"), std::string::npos) << t;
  EXPECT_NE(render_markdown_tables(r, {{"huber", "full"}, false, "peer"}).find(t), std::string::npos);
  EXPECT_TRUE(render_static_ratio_table({rec("walking", "pa", 1, "full", 0.03)}, {"full"}).empty());  // no static
}

TEST(FiguresFromMetrics, ReadsTheLiveTrajectoryAndLocalBaKeys) {
  const nlohmann::json m = {{"ate", {{"rmse", 0.1}}},
                            {"ate_live", {{"rmse", 0.4}, {"max", 1.2}, {"dragged_events", 3}}},
                            {"timings", {{"local_ba", {{"median_ms", 120.0}}}}}};
  const RunFigures f = figures_from_metrics(m);
  EXPECT_DOUBLE_EQ(f.ate_live_rmse_m, 0.4);
  EXPECT_DOUBLE_EQ(f.ate_live_max_m, 1.2);
  EXPECT_DOUBLE_EQ(f.dragged_events, 3.0);
  EXPECT_DOUBLE_EQ(f.local_ba_median_ms, 120.0);
}

TEST(LiveTable, MeanAndWorstRunOfFinalAndLiveWithDraggedEventsSummed) {
  auto live = [](const std::string& path, std::uint64_t seed, double fin, double lv, double drags, double lba) {
    RunRecord r = rec("large_box", path, seed, "full", fin);
    r.figures.ate_live_rmse_m = lv;
    r.figures.dragged_events = drags;
    r.figures.local_ba_median_ms = lba;
    return r;
  };
  std::vector<RunRecord> records = {live("fr2", 1, 0.02, 0.03, 0, 100), live("fr2", 2, 0.04, 0.09, 2, 140),
                                    live("bonn", 1, 0.10, 0.50, 5, 200)};
  RunRecord peer = rec("large_box", "fr2", 1, "peer", 0.30);
  peer.figures.dragged_events = 4;
  records.push_back(peer);
  EXPECT_TRUE(render_live_table({rec("walking", "fr2", 1, "full", 0.01)}, {"full"}).empty());
  const std::string t = render_live_table(records, {"full", "peer"});
  // fr2: final mean 3, worst 4; live mean 6, worst 9; 2 drags; tracking median 30; Local BA median 120.
  EXPECT_NE(t.find("| large_box | fr2 | 3.00 | 4.00 | 6.00 | 9.00 | 2 | 30.0 | 120 | 30.00 | 30.00 | - | - | 4 |"),
            std::string::npos)
      << t;
  EXPECT_NE(t.find("| large_box | bonn | 10.00 | 10.00 | 50.00 | 50.00 | 5 |"), std::string::npos) << t;
  // Over all paths: mean of the three runs, worst run, drags summed.
  EXPECT_NE(t.find("| large_box | all | 5.33 | 10.00 | 20.67 | 50.00 | 7 |"), std::string::npos) << t;
  EXPECT_LT(t.find("| fr2 |"), t.find("| bonn |"));
  EXPECT_LT(t.find("| bonn |"), t.find("| all |"));
}

TEST(Markers, ReplacesOnlyTheGeneratedBlock) {
  const std::string doc = std::string("# B\nintro\n") + kTableBeginMarker + "\nold table\n" + kTableEndMarker + "\nafter\n";
  const std::string out = replace_between_markers(doc, "new table", "B.md");
  EXPECT_EQ(out, std::string("# B\nintro\n") + kTableBeginMarker + "\nnew table\n" + kTableEndMarker + "\nafter\n");
  EXPECT_EQ(replace_between_markers(out, "new table", "B.md"), out);  // idempotent
  try {
    replace_between_markers("# no markers\n", "t", "BENCHMARKS.md");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("BENCHMARKS.md"), std::string::npos);
  }
}

TEST(SummaryHtml, ChartsTablesAndLinksToRunReports) {
  std::vector<RunRecord> r = {rec("walking", "pa", 1, "huber", 0.02), rec("walking", "pa", 1, "full", 0.01)};
  r[0].report_html = "/out/runs/a/huber/report.html";
  r[1].run_dir = "/out/runs/a/full";
  const TableOptions o{{"huber", "full"}, false, "peer"};
  const nlohmann::json results = {{"version", {{"git_describe", "v1-test"}}}, {"wall_seconds", 12.0}};
  const std::string html = render_bench_summary_html(results, r, o, "/out");
  EXPECT_EQ(testing::html_tag_balance_problem(html), "");
  EXPECT_NE(html.find("href=\"runs/a/huber/report.html\""), std::string::npos);
  EXPECT_NE(html.find("href=\"runs/a/full\""), std::string::npos);
  EXPECT_NE(html.find("id=\"chart-ate_rmse_cm\""), std::string::npos);
  EXPECT_NE(html.find("v1-test"), std::string::npos);
  const Plot p = bench_bar_chart(r, o, "ate_rmse_cm", true);
  ASSERT_EQ(p.series().size(), 2u);
  EXPECT_NEAR(p.series()[0].y.at(0), 2.0, 1e-9);
  EXPECT_NEAR(p.series()[1].y.at(0), 1.0, 1e-9);
}

}  // namespace
}  // namespace varslam::report
