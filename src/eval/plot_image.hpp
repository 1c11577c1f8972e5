#pragma once
// The same plot as a raster image (OpenCV drawing), for quick looks and reports that want PNG.
#include <filesystem>
#include <opencv2/core.hpp>

#include "eval/svg_plot.hpp"

namespace varslam {

/// 8-bit BGR image of plot.options().width x height pixels.
cv::Mat render_plot_image(const Plot& plot);
/// Throws InputError when the file cannot be written.
void write_plot_png(const Plot& plot, const std::filesystem::path& file);

}  // namespace varslam
