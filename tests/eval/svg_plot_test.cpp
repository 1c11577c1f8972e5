// The plot writers: well-formed SVG holding every series, sensible ticks, PNG of the right size.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "eval/plot_image.hpp"
#include "eval/plot_layout.hpp"
#include "eval/svg_plot.hpp"

namespace varslam {
namespace {

// Minimal XML check: every element is closed in order and attribute quotes balance.
bool well_formed(const std::string& xml, std::string& why) {
  std::vector<std::string> stack;
  std::size_t pos = 0;
  while ((pos = xml.find('<', pos)) != std::string::npos) {
    const std::size_t end = xml.find('>', pos);
    if (end == std::string::npos) {
      why = "unterminated tag";
      return false;
    }
    const std::string tag = xml.substr(pos + 1, end - pos - 1);
    pos = end + 1;
    if (tag.empty()) {
      why = "empty tag";
      return false;
    }
    if (std::count(tag.begin(), tag.end(), '"') % 2 != 0) {
      why = "unbalanced quotes in <" + tag + ">";
      return false;
    }
    if (tag[0] == '?') continue;
    const bool closing = tag[0] == '/';
    const bool self_closing = tag.back() == '/';
    const std::string body = closing ? tag.substr(1) : tag;
    const std::string name = body.substr(0, body.find_first_of(" /"));
    if (closing) {
      if (stack.empty() || stack.back() != name) {
        why = "unexpected </" + name + ">";
        return false;
      }
      stack.pop_back();
    } else if (!self_closing) {
      stack.push_back(name);
    }
  }
  if (!stack.empty()) why = "unclosed <" + stack.back() + ">";
  return stack.empty();
}

std::size_t count_of(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

Plot two_series_plot() {
  Plot plot({"ATE <error> & more", "time [s]", "error [m]", 640, 480, false, true});
  plot.add_line("ground truth", {0, 1, 2, 3}, {0.0, 0.5, 0.25, 1.0}, "#123456");
  plot.add_scatter("estimate", {0.5, 1.5, 2.5}, {0.1, 0.2, 0.3}, "#abcdef");
  return plot;
}

TEST(SvgPlot, IsWellFormedAndHoldsEverySeries) {
  const std::string svg = render_svg(two_series_plot());
  std::string why;
  EXPECT_TRUE(well_formed(svg, why)) << why;
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"640\" height=\"480\""), std::string::npos);
  EXPECT_NE(svg.find("ATE &lt;error&gt; &amp; more"), std::string::npos);  // escaped title
  EXPECT_NE(svg.find(">time [s]</text>"), std::string::npos);
  EXPECT_NE(svg.find(">error [m]</text>"), std::string::npos);
  EXPECT_NE(svg.find(">ground truth</text>"), std::string::npos);  // legend
  EXPECT_NE(svg.find(">estimate</text>"), std::string::npos);
  // The line is one polyline with its 4 points (plus a legend sample); the scatter 3 dots (+1 in the legend).
  EXPECT_EQ(count_of(svg, "stroke=\"#123456\""), 2u);
  EXPECT_EQ(count_of(svg, "fill=\"#abcdef\""), 4u);
  const std::regex line_re("stroke=\"#123456\"[^>]*points=\"([^\"]*)\"");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(svg, m, line_re));
  EXPECT_EQ(count_of(m[1].str(), ","), 4u);
}

TEST(SvgPlot, MapsDataMonotonicallyIntoThePlotArea) {
  Plot plot({"", "", "", 400, 300, false, false});
  plot.add_line("", {0, 10}, {0, 5}, "#ff0000");
  const std::string svg = render_svg(plot);
  const std::regex line_re("stroke=\"#ff0000\"[^>]*points=\"([-0-9.]+),([-0-9.]+) ([-0-9.]+),([-0-9.]+)\"");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(svg, m, line_re)) << svg;
  const double x0 = std::stod(m[1]), y0 = std::stod(m[2]), x1 = std::stod(m[3]), y1 = std::stod(m[4]);
  EXPECT_LT(x0, x1);
  EXPECT_GT(y0, y1);  // y up in data is up on screen
  for (double v : {x0, x1}) EXPECT_TRUE(v >= 0 && v <= 400);
  for (double v : {y0, y1}) EXPECT_TRUE(v >= 0 && v <= 300);
}

TEST(SvgPlot, EqualAspectUsesTheSameScaleOnBothAxes) {
  Plot plot({"top view", "x [m]", "y [m]", 800, 400, true, false});
  plot.add_line("", {0, 1}, {0, 4}, "#ff0000");  // tall data in a wide plot
  const std::string svg = render_svg(plot);
  const std::regex line_re("stroke=\"#ff0000\"[^>]*points=\"([-0-9.]+),([-0-9.]+) ([-0-9.]+),([-0-9.]+)\"");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(svg, m, line_re));
  const double dx = std::stod(m[3]) - std::stod(m[1]);
  const double dy = std::stod(m[2]) - std::stod(m[4]);
  EXPECT_NEAR(dy / dx, 4.0, 0.05);
}

TEST(SvgPlot, CategoryBarsAreLabelledAndGrouped) {
  Plot plot({"timing", "", "ms", 600, 400, false, true});
  plot.add_category_bars("mean", {"orb", "match", "ba"}, {5.0, 2.0, 12.0});
  plot.add_category_bars("max", {"orb", "match", "ba"}, {8.0, 3.0, 30.0});
  const std::string svg = render_svg(plot);
  std::string why;
  EXPECT_TRUE(well_formed(svg, why)) << why;
  for (const char* name : {">orb<", ">match<", ">ba<", ">mean<", ">max<"}) EXPECT_NE(svg.find(name), std::string::npos) << name;
  // 3 bars per series plus one legend swatch each.
  EXPECT_EQ(count_of(svg, "fill=\"" + palette_color(0) + "\""), 4u);
  EXPECT_EQ(count_of(svg, "fill=\"" + palette_color(1) + "\""), 4u);
  EXPECT_THROW(plot.add_category_bars("other", {"a", "b"}, {1, 2}), std::invalid_argument);
  const auto dir = std::filesystem::path(VARSLAM_BINARY_DIR) / "test_eval_out";
  std::filesystem::create_directories(dir);
  write_plot(plot, dir / "bars.png");  // for a look by eye; the content is checked through the SVG above
  write_plot(plot, dir / "bars.svg");
}

// Long category names (the benchmark's scenario names) must not run into each other: crowded labels alternate
// between two rows, short ones stay on one.
TEST(SvgPlot, CrowdedCategoryLabelsDoNotOverlap) {
  auto label_boxes = [](const std::vector<std::string>& names) {
    Plot plot({"", "", "ms", 640, 400, false, true});
    plot.add_category_bars("a", names, std::vector<double>(names.size(), 1.0));
    const std::string svg = render_svg(plot);
    std::vector<std::pair<double, double>> at;  // (x, y) of each category label, in order
    for (const auto& n : names) {
      const std::regex re("<text x=\"([0-9.]+)\" y=\"([0-9.]+)\"[^>]*>" + n + "</text>");
      std::smatch m;
      EXPECT_TRUE(std::regex_search(svg, m, re)) << n;
      at.emplace_back(std::stod(m[1]), std::stod(m[2]));
    }
    return at;
  };
  const std::vector<std::string> longs = {"static", "walking", "unknown_box", "obstructing_box", "balloon", "mixed",
                                          "7scenes_redkitchen"};
  const auto at = label_boxes(longs);
  for (std::size_t k = 0; k + 1 < at.size(); ++k) {
    const double half_widths = text_width(longs[k], 12.0) / 2 + text_width(longs[k + 1], 12.0) / 2;
    const bool apart = at[k + 1].first - at[k].first >= half_widths || std::abs(at[k + 1].second - at[k].second) >= 12;
    EXPECT_TRUE(apart) << longs[k] << " / " << longs[k + 1];
  }
  const auto short_at = label_boxes({"orb", "match", "ba"});
  EXPECT_DOUBLE_EQ(short_at[0].second, short_at[1].second);  // room enough: one row
  EXPECT_DOUBLE_EQ(short_at[1].second, short_at[2].second);
}

TEST(SvgPlot, MismatchedSeriesIsRejected) {
  Plot plot;
  EXPECT_THROW(plot.add_line("bad", {1, 2, 3}, {1, 2}), std::invalid_argument);
}

TEST(SvgPlot, EmptyAndDegenerateDataStillRender) {
  Plot empty;
  std::string why;
  EXPECT_TRUE(well_formed(render_svg(empty), why)) << why;
  Plot flat;
  flat.add_line("flat", {1, 1, 1}, {2, 2, 2});
  EXPECT_TRUE(well_formed(render_svg(flat), why)) << why;
  EXPECT_EQ(render_svg(flat).find("nan"), std::string::npos);
}

TEST(PlotAxis, NiceTicksCoverTheData) {
  const AxisTicks a = nice_axis(0.013, 0.412, 5);
  EXPECT_LE(a.lo, 0.013);
  EXPECT_GE(a.hi, 0.412);
  EXPECT_DOUBLE_EQ(a.step, 0.1);
  ASSERT_FALSE(a.values.empty());
  EXPECT_DOUBLE_EQ(a.values.front(), 0.0);
  EXPECT_NEAR(a.values.back(), 0.5, 1e-12);
  EXPECT_EQ(format_tick(0.25, 0.05), "0.25");
  EXPECT_EQ(format_tick(20.0, 5.0), "20");
  EXPECT_EQ(format_tick(-1.5, 0.5), "-1.5");
}

TEST(PlotImage, HasThePlotSizeAndTheSeriesColour) {
  const cv::Mat img = render_plot_image(two_series_plot());
  ASSERT_EQ(img.cols, 640);
  ASSERT_EQ(img.rows, 480);
  ASSERT_EQ(img.type(), CV_8UC3);
  cv::Mat mask;
  cv::inRange(img, cv::Scalar(0x56 - 2, 0x34 - 2, 0x12 - 2), cv::Scalar(0x56 + 2, 0x34 + 2, 0x12 + 2), mask);  // BGR
  EXPECT_GT(cv::countNonZero(mask), 100);
}

TEST(PlotFiles, WritesSvgAndPngAndRejectsOtherExtensions) {
  const auto dir = std::filesystem::path(VARSLAM_BINARY_DIR) / "test_eval_out";
  std::filesystem::create_directories(dir);
  write_plot(two_series_plot(), dir / "plot.svg");
  write_plot(two_series_plot(), dir / "plot.png");
  std::ifstream in(dir / "plot.svg");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), render_svg(two_series_plot()));
  EXPECT_GT(std::filesystem::file_size(dir / "plot.png"), 1000u);
  EXPECT_THROW(write_plot(two_series_plot(), dir / "plot.pdf"), InputError);
  EXPECT_THROW(write_plot(two_series_plot(), dir / "no_such_dir" / "plot.svg"), InputError);
}

}  // namespace
}  // namespace varslam
