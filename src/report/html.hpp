#pragma once
// Small building blocks for self-contained HTML pages: escaping, base64 data URIs, inline SVG.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "eval/svg_plot.hpp"

namespace varslam::report {

/// Escapes & < > " ' so any text can go into element content or a quoted attribute.
std::string html_escape(std::string_view text);

/// Standard base64 (RFC 4648, with '=' padding).
std::string base64_encode(const std::vector<std::uint8_t>& bytes);

/// "data:<mime>;base64,..." of a file's bytes; nullopt when the file is missing or unreadable.
std::optional<std::string> file_data_uri(const std::filesystem::path& file, const std::string& mime);

/// An image file as a JPEG data URI, shrunk to at most max_width pixels wide (a preview contact sheet is megabytes
/// as PNG; a report per run must stay small). nullopt when the file is missing or not an image.
std::optional<std::string> image_data_uri(const std::filesystem::path& file, int max_width = 1200);

/// The plot as an <svg> element ready to paste into HTML (the XML prolog of the standalone document dropped).
std::string inline_svg(const Plot& plot);

/// A number for people: fixed decimals, "n/a" when not finite.
std::string format_number(double value, int decimals);

/// The shared <head> (charset, title, one small stylesheet) of every page we write.
std::string page_head(std::string_view title);

}  // namespace varslam::report
