#pragma once
// The observer behind --debug-frames: for the chosen frames, draws the person filter's three stages (all
// keypoints | keypoints in boxes | keypoints kept after the depth test, the paper's Fig. 3) into a PNG.
#include <filesystem>
#include <set>
#include <string>

#include "pipeline/events.hpp"

namespace varslam::run {

class FilterStageWriter final : public Observer {
 public:
  /// `frames`: frame indices of the dataset (the same numbers the CLI's --debug-frames takes).
  FilterStageWriter(std::set<std::size_t> frames, std::filesystem::path out_dir)
      : frames_(std::move(frames)), out_(std::move(out_dir)) {}
  void on_detection(const DetectionEvent& d) override;
  /// The picture's name for a frame index.
  static std::string file_name(std::size_t index);

 private:
  std::set<std::size_t> frames_;
  std::filesystem::path out_;
};

}  // namespace varslam::run
