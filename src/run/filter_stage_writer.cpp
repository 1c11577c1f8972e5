#include "run/filter_stage_writer.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <opencv2/imgcodecs.hpp>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "semantic/filter_stages_image.hpp"

namespace varslam::run {

std::string FilterStageWriter::file_name(std::size_t index) { return fmt::format("semantic_stages_{:06d}.png", index); }

void FilterStageWriter::on_detection(const DetectionEvent& d) {
  const std::size_t index = d.source_index;
  if (!frames_.count(index) || d.bgr.empty()) return;
  const auto file = out_ / file_name(index);
  try {
    write_image_atomically(file, semantic::draw_filter_stages(d.bgr, d.keypoints, d.boxes, d.keep), "filter stages image");
  } catch (const InputError& e) {
    spdlog::warn("{}", e.what());  // a debug picture: the run goes on without it
  }
}

}  // namespace varslam::run
