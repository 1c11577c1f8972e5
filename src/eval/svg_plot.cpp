#include "eval/svg_plot.hpp"

#include <array>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "eval/plot_image.hpp"
#include "eval/plot_layout.hpp"

namespace varslam {
namespace {

std::string xml_escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

// Two decimals of a pixel is far below what anyone sees and keeps big trajectories small.
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

class SvgCanvas final : public PlotCanvas {
 public:
  SvgCanvas(int width, int height) {
    out_ += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    out_ += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(width) + "\" height=\"" +
            std::to_string(height) + "\" viewBox=\"0 0 " + std::to_string(width) + " " + std::to_string(height) +
            "\" font-family=\"DejaVu Sans, Arial, sans-serif\">\n";
  }
  void polyline(const std::vector<CanvasPoint>& points, const std::string& color, double width) override {
    out_ += "<polyline fill=\"none\" stroke=\"" + xml_escape(color) + "\" stroke-width=\"" + num(width) +
            "\" stroke-linejoin=\"round\" points=\"";
    for (std::size_t k = 0; k < points.size(); ++k) {
      if (k) out_ += ' ';
      out_ += num(points[k].x) + ',' + num(points[k].y);
    }
    out_ += "\"/>\n";
  }
  void circle(CanvasPoint c, double radius, const std::string& color) override {
    out_ += "<circle cx=\"" + num(c.x) + "\" cy=\"" + num(c.y) + "\" r=\"" + num(radius) + "\" fill=\"" +
            xml_escape(color) + "\"/>\n";
  }
  void rect(double x, double y, double w, double h, const std::string& fill, const std::string& stroke) override {
    out_ += "<rect x=\"" + num(x) + "\" y=\"" + num(y) + "\" width=\"" + num(w) + "\" height=\"" + num(h) +
            "\" fill=\"" + (fill.empty() ? std::string("none") : xml_escape(fill)) + "\"";
    if (!stroke.empty()) out_ += " stroke=\"" + xml_escape(stroke) + "\" stroke-width=\"1\"";
    out_ += "/>\n";
  }
  void text(CanvasPoint at, const std::string& s, double size, TextAnchor anchor, bool vertical, bool bold) override {
    static const std::array<const char*, 3> anchors{"start", "middle", "end"};
    out_ += "<text x=\"" + num(at.x) + "\" y=\"" + num(at.y) + "\" font-size=\"" + num(size) + "\" text-anchor=\"" +
            anchors[static_cast<std::size_t>(anchor)] + "\"";
    if (bold) out_ += " font-weight=\"bold\"";
    if (vertical) out_ += " transform=\"rotate(-90 " + num(at.x) + " " + num(at.y) + ")\"";
    out_ += ">" + xml_escape(s) + "</text>\n";
  }
  std::string finish() {
    out_ += "</svg>\n";
    return std::move(out_);
  }

 private:
  std::string out_;
};

}  // namespace

Plot& Plot::add_series(PlotSeries series) {
  if (series.x.size() != series.y.size()) {
    throw std::invalid_argument("Plot series '" + series.label + "': x and y differ in length");
  }
  series_.push_back(std::move(series));
  return *this;
}

Plot& Plot::add_line(std::string label, std::vector<double> x, std::vector<double> y, std::string color) {
  return add_series({std::move(label), std::move(x), std::move(y), SeriesStyle::Line, std::move(color), 1.5});
}

Plot& Plot::add_scatter(std::string label, std::vector<double> x, std::vector<double> y, std::string color) {
  return add_series({std::move(label), std::move(x), std::move(y), SeriesStyle::Scatter, std::move(color), 1.5});
}

Plot& Plot::add_bars(std::string label, std::vector<double> x, std::vector<double> heights, std::string color) {
  return add_series({std::move(label), std::move(x), std::move(heights), SeriesStyle::Bar, std::move(color), 1.0});
}

Plot& Plot::add_category_bars(std::string label, const std::vector<std::string>& categories,
                              std::vector<double> heights, std::string color) {
  if (x_categories_.empty()) x_categories_ = categories;
  if (categories != x_categories_) {
    throw std::invalid_argument("Plot series '" + label + "': categories differ from the earlier bar series");
  }
  std::vector<double> x(categories.size());
  for (std::size_t k = 0; k < x.size(); ++k) x[k] = static_cast<double>(k);
  return add_bars(std::move(label), std::move(x), std::move(heights), std::move(color));
}

std::string palette_color(std::size_t k) {
  static const std::array<const char*, 10> colors{"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                                  "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
  return colors[k % colors.size()];
}

std::string render_svg(const Plot& plot) {
  SvgCanvas canvas(plot.options().width, plot.options().height);
  draw_plot(plot, canvas);
  return canvas.finish();
}

void write_plot(const Plot& plot, const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".png") {
    write_plot_png(plot, file);
    return;
  }
  if (ext != ".svg") {
    throw InputError(file.string() + ": unknown plot format '" + ext + "' (use .svg or .png)");
  }
  write_file_atomically(file, render_svg(plot), "plot");
}

}  // namespace varslam
