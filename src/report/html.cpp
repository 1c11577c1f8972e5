#include "report/html.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace varslam::report {

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string base64_encode(const std::vector<std::uint8_t>& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest == 1) {
    const std::uint32_t v = std::uint32_t{bytes[i]} << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (rest == 2) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

std::optional<std::string> file_data_uri(const std::filesystem::path& file, const std::string& mime) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (bytes.empty()) return std::nullopt;
  return "data:" + mime + ";base64," + base64_encode(bytes);
}

std::optional<std::string> image_data_uri(const std::filesystem::path& file, int max_width) {
  if (!std::filesystem::exists(file)) return std::nullopt;
  cv::Mat img = cv::imread(file.string(), cv::IMREAD_COLOR);
  if (img.empty()) return std::nullopt;
  if (max_width > 0 && img.cols > max_width) {
    const double s = static_cast<double>(max_width) / img.cols;
    cv::resize(img, img, cv::Size(), s, s, cv::INTER_AREA);
  }
  std::vector<std::uint8_t> bytes;
  if (!cv::imencode(".jpg", img, bytes, {cv::IMWRITE_JPEG_QUALITY, 85})) return std::nullopt;
  return "data:image/jpeg;base64," + base64_encode(bytes);
}

std::string inline_svg(const Plot& plot) {
  std::string svg = render_svg(plot);
  const auto start = svg.find("<svg");
  return start == std::string::npos ? svg : svg.substr(start);
}

std::string format_number(double value, int decimals) {
  if (!std::isfinite(value)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

std::string page_head(std::string_view title) {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" + html_escape(title) +
         "</title>\n<style>\n"
         "body{font-family:'DejaVu Sans',Arial,sans-serif;margin:24px;color:#222;max-width:1700px}\n"
         "h1{font-size:22px}h2{font-size:18px;margin-top:28px;border-bottom:1px solid #ccc}\n"
         "table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #bbb;padding:3px 8px;"
         "text-align:right;font-size:13px}th{background:#eee}td.l,th.l{text-align:left}\n"
         ".plots{display:flex;flex-wrap:wrap;gap:12px;align-items:flex-start}figure{margin:0}.plots svg{border:1px solid #ddd;background:#fff}\n"
         ".note{color:#666;font-size:13px}img.preview{max-width:100%;border:1px solid #ddd}\n"
         "code{background:#f4f4f4;padding:1px 4px;font-size:12px}pre{overflow-x:auto;font-size:12px}\n"
         "</style>\n</head>\n";
}

}  // namespace varslam::report
