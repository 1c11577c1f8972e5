#include "eval/plot_image.hpp"

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "eval/plot_layout.hpp"

namespace varslam {
namespace {

cv::Scalar bgr(const std::string& color) {
  const Rgb c = parse_color(color);
  return {static_cast<double>(c.b), static_cast<double>(c.g), static_cast<double>(c.r)};
}

cv::Point pt(CanvasPoint p) { return {static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))}; }

class MatCanvas final : public PlotCanvas {
 public:
  MatCanvas(int width, int height) : img_(height, width, CV_8UC3, cv::Scalar(255, 255, 255)) {}
  void polyline(const std::vector<CanvasPoint>& points, const std::string& color, double width) override {
    std::vector<cv::Point> p;
    p.reserve(points.size());
    for (const auto& q : points) p.push_back(pt(q));
    cv::polylines(img_, p, false, bgr(color), thickness(width), cv::LINE_AA);
  }
  void circle(CanvasPoint c, double radius, const std::string& color) override {
    cv::circle(img_, pt(c), std::max(1, static_cast<int>(std::lround(radius))), bgr(color), cv::FILLED, cv::LINE_AA);
  }
  void rect(double x, double y, double w, double h, const std::string& fill, const std::string& stroke) override {
    const cv::Rect r(pt({x, y}), pt({x + w, y + h}));
    if (!fill.empty()) cv::rectangle(img_, r, bgr(fill), cv::FILLED);
    if (!stroke.empty()) cv::rectangle(img_, r, bgr(stroke), 1);
  }
  void text(CanvasPoint at, const std::string& s, double size, TextAnchor anchor, bool vertical, bool bold) override {
    const int font = cv::FONT_HERSHEY_SIMPLEX;
    const double scale = size / 30.0;  // Hershey simplex caps are about 22 px tall at scale 1
    const int thick = bold ? 2 : 1;
    int baseline = 0;
    const cv::Size ts = cv::getTextSize(s, font, scale, thick, &baseline);
    const double shift = anchor == TextAnchor::Start ? 0.0 : anchor == TextAnchor::Middle ? 0.5 * ts.width : ts.width;
    if (!vertical) {
      cv::putText(img_, s, pt({at.x - shift, at.y}), font, scale, cv::Scalar(30, 30, 30), thick, cv::LINE_AA);
      return;
    }
    // Draw horizontally into a patch, turn it, and darken the target with it (background is white).
    cv::Mat patch(ts.height + baseline + 2, ts.width + 2, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::putText(patch, s, {1, ts.height + 1}, font, scale, cv::Scalar(30, 30, 30), thick, cv::LINE_AA);
    cv::Mat turned;
    cv::rotate(patch, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int x0 = static_cast<int>(std::lround(at.x)) - turned.cols;
    const int y0 = static_cast<int>(std::lround(at.y - (ts.width - shift)));
    const cv::Rect dst = cv::Rect(x0, y0, turned.cols, turned.rows) & cv::Rect(0, 0, img_.cols, img_.rows);
    if (dst.empty()) return;
    const cv::Rect src(dst.x - x0, dst.y - y0, dst.width, dst.height);
    cv::Mat roi = img_(dst);
    cv::min(roi, turned(src), roi);
  }
  const cv::Mat& image() const { return img_; }

 private:
  static int thickness(double w) { return std::max(1, static_cast<int>(std::lround(w))); }
  cv::Mat img_;
};

}  // namespace

cv::Mat render_plot_image(const Plot& plot) {
  MatCanvas canvas(plot.options().width, plot.options().height);
  draw_plot(plot, canvas);
  return canvas.image();
}

void write_plot_png(const Plot& plot, const std::filesystem::path& file) {
  write_image_atomically(file, render_plot_image(plot), "plot");
}

}  // namespace varslam
