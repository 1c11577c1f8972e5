#pragma once
// A small self-written 2-D plot description (lines, scatter points, bars; title, axis labels, legend) that the SVG and
// PNG writers render identically. Deliberately tiny: enough for trajectory top views, errors over time,
// per-keyframe values and per-stage timing bars.
#include <filesystem>
#include <string>
#include <vector>

namespace varslam {

enum class SeriesStyle { Line, Scatter, Bar };

struct PlotSeries {
  std::string label;  // shown in the legend; empty = not listed
  std::vector<double> x;
  std::vector<double> y;
  SeriesStyle style = SeriesStyle::Line;
  std::string color;  // "#rrggbb"; empty = next palette colour
  double width = 1.5;  // line width or marker radius, pixels
};

struct PlotOptions {
  std::string title;
  std::string x_label;
  std::string y_label;
  int width = 800;   // pixels
  int height = 560;
  bool equal_aspect = false;  // one data unit is as long on x as on y (top views)
  bool legend = true;
};

class Plot {
 public:
  explicit Plot(PlotOptions options = {}) : options_(std::move(options)) {}

  Plot& add_line(std::string label, std::vector<double> x, std::vector<double> y, std::string color = {});
  Plot& add_scatter(std::string label, std::vector<double> x, std::vector<double> y, std::string color = {});
  /// Bars at positions x (several bar series side by side at the same x are grouped).
  Plot& add_bars(std::string label, std::vector<double> x, std::vector<double> heights, std::string color = {});
  /// Bars named by category: bar k is drawn at x = k and the x axis is labelled with the names.
  Plot& add_category_bars(std::string label, const std::vector<std::string>& categories, std::vector<double> heights,
                          std::string color = {});
  Plot& add_series(PlotSeries series);

  const PlotOptions& options() const { return options_; }
  PlotOptions& options() { return options_; }
  const std::vector<PlotSeries>& series() const { return series_; }
  /// Non-empty when the x axis shows category names instead of numbers.
  const std::vector<std::string>& x_categories() const { return x_categories_; }

 private:
  PlotOptions options_;
  std::vector<PlotSeries> series_;
  std::vector<std::string> x_categories_;
};

/// The colour of the k-th series when none is given (a ten-colour qualitative palette).
std::string palette_color(std::size_t k);

/// The plot as a standalone SVG document.
std::string render_svg(const Plot& plot);
/// Writes SVG or PNG depending on the extension (.svg / .png); throws InputError on another extension
/// or when the file cannot be written.
void write_plot(const Plot& plot, const std::filesystem::path& file);

}  // namespace varslam
