#pragma once
// The pixel layouts of ROS image messages, decoded to and encoded from OpenCV matrices. No ROS types: the bag
// reader hands the message fields over, so this is tested and fuzzed on plain bytes.
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace varslam::ros_image {

/// sensor_msgs/Image fields to a matrix: rgb8/rgba8/bgr8/bgra8 -> CV_8UC3 BGR, mono8 -> CV_8UC1, 16UC1/mono16 ->
/// CV_16UC1, 32FC1 -> CV_32FC1. Throws varslam::InputError (prefixed with `where`) on an unknown encoding or a
/// step or data size that does not hold the image.
cv::Mat decode_raw_image(const std::string& encoding, std::uint32_t width, std::uint32_t height, std::uint32_t step,
                         bool big_endian, const std::uint8_t* data, std::size_t size, const std::string& where);

/// sensor_msgs/CompressedImage to a matrix. Colour ("jpeg", "png", "rgb8; jpeg compressed bgr8", ...) -> CV_8UC3
/// BGR; "16UC1; compressedDepth[ png]" -> CV_16UC1; "32FC1; compressedDepth[ png]" -> CV_32FC1 metres (the
/// inverse-depth quantisation of image_transport's compressedDepth). Only PNG and JPEG data reach the decoder.
cv::Mat decode_compressed_image(const std::string& format, const std::uint8_t* data, std::size_t size,
                                const std::string& where);

/// True for a CompressedImage format that holds depth.
bool is_compressed_depth(const std::string& format);

/// A CV_16UC1 image as compressedDepth data: the 12-byte header (format 0, no quantisation) and a PNG.
std::vector<std::uint8_t> encode_compressed_depth(const cv::Mat& depth16);

/// Bytes per pixel of a raw encoding (0 when unknown).
int raw_bytes_per_pixel(const std::string& encoding);

}  // namespace varslam::ros_image
