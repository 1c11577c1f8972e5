#pragma once
// Shared by the SVG and PNG plot writers: the drawing primitives a backend provides, and the one function
// that lays a Plot out (ranges, ticks, legend) and draws it with them, so both outputs look the same.
#include <string>
#include <vector>

#include "eval/svg_plot.hpp"

namespace varslam {

struct CanvasPoint {
  double x = 0.0;
  double y = 0.0;  // pixels, y grows downwards
};

enum class TextAnchor { Start, Middle, End };

struct Rgb {
  int r = 0, g = 0, b = 0;
};
/// "#rrggbb" or "#rgb"; anything else is black.
Rgb parse_color(const std::string& color);

class PlotCanvas {
 public:
  virtual ~PlotCanvas() = default;
  virtual void polyline(const std::vector<CanvasPoint>& points, const std::string& color, double width) = 0;
  virtual void circle(CanvasPoint centre, double radius, const std::string& color) = 0;
  virtual void rect(double x, double y, double w, double h, const std::string& fill, const std::string& stroke) = 0;
  /// y is the text baseline; vertical text reads bottom-to-top and is anchored around (x, y).
  virtual void text(CanvasPoint at, const std::string& s, double size, TextAnchor anchor, bool vertical,
                    bool bold) = 0;
};

/// Evenly spaced "nice" tick values (1, 2 or 5 times a power of ten) covering [lo, hi].
struct AxisTicks {
  double lo = 0.0;
  double hi = 1.0;
  double step = 0.2;
  std::vector<double> values;
};
/// Ticks for data in [data_min, data_max]; the axis range is widened to whole steps.
AxisTicks nice_axis(double data_min, double data_max, int target_ticks);
/// Tick label with as many decimals as the step needs ("0.25", "10", "-1.5").
std::string format_tick(double value, double step);

/// Estimated width in pixels of `s` at font `size` (sans-serif average; used to keep labels apart).
double text_width(const std::string& s, double size);

void draw_plot(const Plot& plot, PlotCanvas& canvas);

}  // namespace varslam
