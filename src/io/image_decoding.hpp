#pragma once
// Decoding of the image files RGB-D datasets store, with the pixels cv::imdecode gives, in less time: a colour
// JPEG straight into BGR order (OpenCV's own path decodes to RGB and then swaps every pixel) and a 16-bit
// greyscale PNG inflated by libdeflate. Other PNGs and JPEGs go to cv::imdecode, once their headers declare a
// plausible size; anything else is no image. Nothing here throws.
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <vector>

namespace varslam {

/// Whether the bytes start with the PNG signature, or with a JPEG's start-of-image marker and a segment.
bool is_png(std::span<const std::uint8_t> bytes);
bool is_jpeg(std::span<const std::uint8_t> bytes);

/// A PNG or JPEG that OpenCV will read as one: OpenCV also tries its DICOM reader, which recognises "DICM" at byte
/// 128 whatever the signature and aborts the process on a damaged file, so such bytes are not one.
bool is_png_or_jpeg_file(std::span<const std::uint8_t> bytes);

/// The bytes of `file`; std::nullopt when it cannot be opened or read.
std::optional<std::vector<std::uint8_t>> read_file_bytes(const std::filesystem::path& file);

/// cv::imdecode(bytes, cv::IMREAD_COLOR): a CV_8UC3 BGR image, or an empty Mat when the bytes are no image (or a
/// damaged one: the fast paths may read a stream zlib would refuse, e.g. one with reserved deflate codes).
cv::Mat decode_colour_image(std::span<const std::uint8_t> bytes);

/// cv::imdecode(bytes, cv::IMREAD_UNCHANGED): the image as stored, or an empty Mat when the bytes are no image.
cv::Mat decode_unchanged_image(std::span<const std::uint8_t> bytes);

/// The fast paths on their own (for their tests): the image when `bytes` is the kind the path handles and decodes
/// cleanly, std::nullopt for anything else (the callers above then ask cv::imdecode).
std::optional<cv::Mat> decode_ycbcr_jpeg_to_bgr(std::span<const std::uint8_t> bytes);
std::optional<cv::Mat> decode_grey16_png(std::span<const std::uint8_t> bytes);

}  // namespace varslam
