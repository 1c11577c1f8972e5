#include "run/filter_stage_writer.hpp"

#include <fmt/format.h>

#include <opencv2/imgcodecs.hpp>

#include "semantic/filter_stages_image.hpp"

namespace varslam::run {

void FilterStageWriter::on_detection(const DetectionEvent& d) {
  const std::size_t index = d.source_index;
  if (!frames_.count(index) || d.bgr.empty()) return;
  const auto file = out_ / fmt::format("semantic_stages_{:06d}.png", index);
  cv::imwrite(file.string(), semantic::draw_filter_stages(d.bgr, d.keypoints, d.boxes, d.keep));
}

}  // namespace varslam::run
