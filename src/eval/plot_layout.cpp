#include "eval/plot_layout.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

namespace varslam {
namespace {

constexpr double kMarginLeft = 78.0;
constexpr double kMarginRight = 24.0;
constexpr double kMarginTop = 44.0;
constexpr double kMarginBottom = 58.0;
constexpr double kTickFont = 12.0;
constexpr double kLabelFont = 14.0;
constexpr double kTitleFont = 17.0;

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

double nice_step(double range, int target_ticks) {
  const double raw = range / std::max(1, target_ticks);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  const double nice = f < 1.5 ? 1.0 : f < 3.0 ? 2.0 : f < 7.0 ? 5.0 : 10.0;
  return nice * mag;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return lo > hi; }
};

// Side-by-side placement of bar series: bar k of group g sits at x + offset(g), width `bar_width`.
struct BarLayout {
  std::size_t groups = 0;
  double spacing = 1.0;
  double bar_width = 0.8;
  double offset(std::size_t group) const {
    return -0.4 * spacing + (static_cast<double>(group) + 0.5) * bar_width;
  }
};

BarLayout bar_layout(const Plot& plot) {
  BarLayout b;
  std::vector<double> xs;
  for (const auto& s : plot.series()) {
    if (s.style != SeriesStyle::Bar) continue;
    ++b.groups;
    xs.insert(xs.end(), s.x.begin(), s.x.end());
  }
  std::sort(xs.begin(), xs.end());
  double spacing = std::numeric_limits<double>::infinity();
  for (std::size_t k = 1; k < xs.size(); ++k) {
    if (xs[k] > xs[k - 1]) spacing = std::min(spacing, xs[k] - xs[k - 1]);
  }
  b.spacing = std::isfinite(spacing) ? spacing : 1.0;
  b.bar_width = b.groups ? 0.8 * b.spacing / static_cast<double>(b.groups) : 0.8;
  return b;
}

// Equal aspect: widen the range that has fewer units per pixel so both match.
void widen_to(AxisTicks& axis, double units, int target_ticks) {
  const double centre = 0.5 * (axis.lo + axis.hi);
  const double lo = centre - 0.5 * units;
  const double hi = centre + 0.5 * units;
  axis.step = nice_step(hi - lo, target_ticks);
  axis.lo = lo;
  axis.hi = hi;
  axis.values.clear();
  for (double v = std::ceil(lo / axis.step) * axis.step; v <= hi + 1e-9 * axis.step; v += axis.step) {
    axis.values.push_back(std::abs(v) < 1e-9 * axis.step ? 0.0 : v);
  }
}

}  // namespace

double text_width(const std::string& s, double size) { return 0.62 * size * static_cast<double>(s.size()); }

Rgb parse_color(const std::string& color) {
  Rgb c;
  if (color.size() == 7 && color[0] == '#') {
    int v[6];
    for (int k = 0; k < 6; ++k) {
      v[k] = hex_digit(color[static_cast<std::size_t>(k) + 1]);
      if (v[k] < 0) return {};
    }
    return {v[0] * 16 + v[1], v[2] * 16 + v[3], v[4] * 16 + v[5]};
  }
  if (color.size() == 4 && color[0] == '#') {
    int v[3];
    for (int k = 0; k < 3; ++k) {
      v[k] = hex_digit(color[static_cast<std::size_t>(k) + 1]);
      if (v[k] < 0) return {};
    }
    return {v[0] * 17, v[1] * 17, v[2] * 17};
  }
  return c;
}

AxisTicks nice_axis(double data_min, double data_max, int target_ticks) {
  if (!std::isfinite(data_min) || !std::isfinite(data_max) || data_min > data_max) {
    data_min = 0.0;
    data_max = 1.0;
  }
  if (data_max - data_min <= 1e-12 * std::max(1.0, std::abs(data_max))) {
    const double pad = std::max(0.5, 0.1 * std::abs(data_max));
    data_min -= pad;
    data_max += pad;
  }
  AxisTicks a;
  a.step = nice_step(data_max - data_min, target_ticks);
  a.lo = std::floor(data_min / a.step + 1e-9) * a.step;
  a.hi = std::ceil(data_max / a.step - 1e-9) * a.step;
  const auto n = static_cast<int>(std::lround((a.hi - a.lo) / a.step));
  for (int k = 0; k <= n; ++k) {
    const double v = a.lo + k * a.step;
    a.values.push_back(std::abs(v) < 1e-9 * a.step ? 0.0 : v);
  }
  return a;
}

std::string format_tick(double value, double step) {
  char buf[64];
  if (std::abs(value) >= 1e6 || (step > 0.0 && step < 1e-4)) {
    std::snprintf(buf, sizeof buf, "%.3g", value);
  } else {
    const int decimals = step > 0.0 ? std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9))) : 2;
    std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  }
  return buf;
}

void draw_plot(const Plot& plot, PlotCanvas& canvas) {
  const auto& opt = plot.options();
  const double W = opt.width;
  const double H = opt.height;
  const double left = kMarginLeft;
  const double top = opt.title.empty() ? kMarginTop * 0.5 : kMarginTop;
  const double pw = std::max(10.0, W - kMarginLeft - kMarginRight);
  const double ph = std::max(10.0, H - top - kMarginBottom);
  const BarLayout bars = bar_layout(plot);
  const bool categories = !plot.x_categories().empty();

  // Data ranges (bars also cover their width and the zero line).
  Range rx;
  Range ry;
  for (const auto& s : plot.series()) {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    for (std::size_t k = 0; k < n; ++k) {
      if (!std::isfinite(s.x[k]) || !std::isfinite(s.y[k])) continue;
      rx.add(s.x[k]);
      ry.add(s.y[k]);
      if (s.style == SeriesStyle::Bar) {
        rx.add(s.x[k] - 0.5 * bars.spacing);
        rx.add(s.x[k] + 0.5 * bars.spacing);
        ry.add(0.0);
      }
    }
  }
  const int target_x = std::max(3, static_cast<int>(pw / 110.0));
  const int target_y = std::max(3, static_cast<int>(ph / 70.0));
  AxisTicks ax;
  if (categories) {
    const auto n = plot.x_categories().size();
    ax.lo = -0.5;
    ax.hi = static_cast<double>(n) - 0.5;
    ax.step = 1.0;
    for (std::size_t k = 0; k < n; ++k) ax.values.push_back(static_cast<double>(k));
  } else {
    ax = nice_axis(rx.lo, rx.hi, target_x);
    if (bars.groups > 0 && !rx.empty()) {  // keep bars snug instead of padding to whole ticks
      ax.lo = std::max(ax.lo, rx.lo);
      ax.hi = std::min(ax.hi, rx.hi);
      ax.values.erase(std::remove_if(ax.values.begin(), ax.values.end(),
                                     [&](double v) { return v < ax.lo - 1e-9 || v > ax.hi + 1e-9; }),
                      ax.values.end());
    }
  }
  // A little headroom so lines do not run along the frame.
  if (!ry.empty()) {
    const double pad = 0.04 * (ry.hi - ry.lo);
    // Never pad across zero: non-negative data (errors, timings) keeps zero as the axis floor.
    ry.lo = ry.lo >= 0.0 ? std::max(0.0, ry.lo - pad) : ry.lo - pad;
    ry.hi = ry.hi <= 0.0 ? std::min(0.0, ry.hi + pad) : ry.hi + pad;
  }
  AxisTicks ay = nice_axis(ry.lo, ry.hi, target_y);
  if (opt.equal_aspect && !categories) {
    const double ux = (ax.hi - ax.lo) / pw;
    const double uy = (ay.hi - ay.lo) / ph;
    if (ux > uy) widen_to(ay, ux * ph, target_y);
    else widen_to(ax, uy * pw, target_x);
  }
  auto px = [&](double x) { return left + (x - ax.lo) / (ax.hi - ax.lo) * pw; };
  auto py = [&](double y) { return top + ph - (y - ay.lo) / (ay.hi - ay.lo) * ph; };

  // Frame, grid and ticks.
  canvas.rect(0, 0, W, H, "#ffffff", "");
  for (double v : ay.values) {
    canvas.polyline({{left, py(v)}, {left + pw, py(v)}}, "#e5e5e5", 1.0);
    canvas.text({left - 7, py(v) + 4}, format_tick(v, ay.step), kTickFont, TextAnchor::End, false, false);
  }
  // Category names wider than their slot alternate between two rows, so neighbours do not overlap.
  bool stagger = false;
  if (categories && !ax.values.empty()) {
    const double slot = pw / static_cast<double>(ax.values.size());
    for (const auto& c : plot.x_categories()) stagger = stagger || text_width(c, kTickFont) > slot - 4.0;
  }
  for (std::size_t k = 0; k < ax.values.size(); ++k) {
    const double v = ax.values[k];
    if (!categories) canvas.polyline({{px(v), top}, {px(v), top + ph}}, "#e5e5e5", 1.0);
    const double row = stagger && k % 2 == 1 ? kTickFont + 2.0 : 0.0;
    canvas.polyline({{px(v), top + ph}, {px(v), top + ph + 5 + row}}, "#333333", 1.0);
    const std::string label = categories ? plot.x_categories()[k] : format_tick(v, ax.step);
    canvas.text({px(v), top + ph + 19 + row}, label, kTickFont, TextAnchor::Middle, false, false);
  }
  if (ay.lo < 0.0 && ay.hi > 0.0 && bars.groups > 0) {
    canvas.polyline({{left, py(0)}, {left + pw, py(0)}}, "#333333", 1.0);
  }
  canvas.rect(left, top, pw, ph, "", "#333333");

  // Series, in the order added.
  std::size_t bar_group = 0;
  std::vector<std::string> colors;
  std::vector<CanvasPoint> occupied;  // where data is drawn, to keep the legend off it
  for (std::size_t si = 0; si < plot.series().size(); ++si) {
    const auto& s = plot.series()[si];
    const std::string color = s.color.empty() ? palette_color(si) : s.color;
    colors.push_back(color);
    const std::size_t n = std::min(s.x.size(), s.y.size());
    if (s.style == SeriesStyle::Line) {
      std::vector<CanvasPoint> run;  // non-finite values break the line
      for (std::size_t k = 0; k <= n; ++k) {
        if (k < n && std::isfinite(s.x[k]) && std::isfinite(s.y[k])) {
          if (!run.empty()) {  // sample long segments too, not only their ends
            const CanvasPoint a = run.back();
            const CanvasPoint b{px(s.x[k]), py(s.y[k])};
            const int steps = std::min(50, static_cast<int>(std::hypot(b.x - a.x, b.y - a.y) / 10.0));
            for (int i = 1; i < steps; ++i) occupied.push_back({a.x + (b.x - a.x) * i / steps, a.y + (b.y - a.y) * i / steps});
          }
          run.push_back({px(s.x[k]), py(s.y[k])});
          occupied.push_back(run.back());
        } else if (!run.empty()) {
          if (run.size() == 1) canvas.circle(run.front(), s.width, color);
          else canvas.polyline(run, color, s.width);
          run.clear();
        }
      }
    } else if (s.style == SeriesStyle::Scatter) {
      for (std::size_t k = 0; k < n; ++k) {
        if (!std::isfinite(s.x[k]) || !std::isfinite(s.y[k])) continue;
        occupied.push_back({px(s.x[k]), py(s.y[k])});
        canvas.circle(occupied.back(), s.width + 1.0, color);
      }
    } else {
      for (std::size_t k = 0; k < n; ++k) {
        if (!std::isfinite(s.x[k]) || !std::isfinite(s.y[k])) continue;
        const double x0 = px(s.x[k] + bars.offset(bar_group) - 0.5 * bars.bar_width);
        const double x1 = px(s.x[k] + bars.offset(bar_group) + 0.5 * bars.bar_width);
        const double y0 = py(std::max(0.0, s.y[k]));
        const double y1 = py(std::min(0.0, s.y[k]));
        canvas.rect(x0, y0, x1 - x0, y1 - y0, color, "");
        for (int i = 0; i <= 8; ++i) {
          for (int m = 0; m <= 4; ++m) occupied.push_back({x0 + (x1 - x0) * m / 4.0, y0 + (y1 - y0) * i / 8.0});
        }
      }
      ++bar_group;
    }
  }

  // Legend in the top-right corner of the plot area.
  if (opt.legend) {
    double widest = 0.0;
    std::size_t entries = 0;
    for (const auto& s : plot.series()) {
      if (s.label.empty()) continue;
      widest = std::max(widest, text_width(s.label, kTickFont));
      ++entries;
    }
    if (entries > 0) {
      const double row = 18.0;
      const double bw = widest + 44.0;
      const double bh = row * static_cast<double>(entries) + 8.0;
      // The corner of the plot area that hides the fewest data points (top right on a tie).
      const std::array<CanvasPoint, 4> corners{CanvasPoint{left + pw - bw - 8.0, top + 8.0},
                                               CanvasPoint{left + 8.0, top + 8.0},
                                               CanvasPoint{left + pw - bw - 8.0, top + ph - bh - 8.0},
                                               CanvasPoint{left + 8.0, top + ph - bh - 8.0}};
      std::array<std::size_t, 4> hidden{};
      for (std::size_t c = 0; c < corners.size(); ++c) {
        for (const auto& q : occupied) {
          if (q.x >= corners[c].x && q.x <= corners[c].x + bw && q.y >= corners[c].y && q.y <= corners[c].y + bh) {
            ++hidden[c];
          }
        }
      }
      const auto best = static_cast<std::size_t>(std::min_element(hidden.begin(), hidden.end()) - hidden.begin());
      const double bx = corners[best].x;
      const double by = corners[best].y;
      canvas.rect(bx, by, bw, bh, "#ffffff", "#999999");
      double y = by + 4.0 + 0.5 * row;
      for (std::size_t si = 0; si < plot.series().size(); ++si) {
        const auto& s = plot.series()[si];
        if (s.label.empty()) continue;
        if (s.style == SeriesStyle::Line) canvas.polyline({{bx + 8, y}, {bx + 30, y}}, colors[si], std::max(2.0, s.width));
        else if (s.style == SeriesStyle::Scatter) canvas.circle({bx + 19, y}, 4.0, colors[si]);
        else canvas.rect(bx + 13, y - 6, 12, 12, colors[si], "");
        canvas.text({bx + 36, y + 4}, s.label, kTickFont, TextAnchor::Start, false, false);
        y += row;
      }
    }
  }

  // Title and axis labels.
  if (!opt.title.empty()) canvas.text({W / 2, 0.5 * kMarginTop + 6}, opt.title, kTitleFont, TextAnchor::Middle, false, true);
  if (!opt.x_label.empty()) canvas.text({left + pw / 2, H - 14}, opt.x_label, kLabelFont, TextAnchor::Middle, false, false);
  if (!opt.y_label.empty()) canvas.text({20, top + ph / 2}, opt.y_label, kLabelFont, TextAnchor::Middle, true, false);
}

}  // namespace varslam
