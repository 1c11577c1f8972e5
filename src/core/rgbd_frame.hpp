#pragma once
// One decoded RGB-D frame as the readers hand it to the pipeline.
#include <cstddef>
#include <opencv2/core.hpp>
#include <string>

namespace varslam {

struct RgbdFrame {
  std::size_t index = 0;   // position in the dataset's frame list
  double timestamp = 0.0;  // seconds (the rgb image's timestamp)
  cv::Mat bgr;             // CV_8UC3
  cv::Mat gray;            // CV_8UC1
  cv::Mat depth;           // CV_32FC1 in metres; 0 where there is no valid depth
  cv::Mat mover_mask;      // optional CV_8UC1 of the image's size: non-zero pixels show movers, no keypoints there
  bool depth_in_colour_frame = false;  // set once depth was registered to the colour camera (Pipeline::frame_preparation)
  std::string rgb_path;
  std::string depth_path;
};

}  // namespace varslam
