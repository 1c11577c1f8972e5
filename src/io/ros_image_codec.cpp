#include "io/ros_image_codec.hpp"

#include <algorithm>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.hpp"
#include "io/image_decoding.hpp"

namespace varslam::ros_image {
namespace {

constexpr std::size_t kCompressedDepthHeader = 12;  // int32 format, float depthQuantA, float depthQuantB

}  // namespace

int raw_bytes_per_pixel(const std::string& e) {
  if (e == "rgb8" || e == "bgr8" || e == "8UC3") return 3;
  if (e == "rgba8" || e == "bgra8" || e == "8UC4") return 4;
  if (e == "mono8" || e == "8UC1") return 1;
  if (e == "16UC1" || e == "mono16") return 2;
  if (e == "32FC1") return 4;
  return 0;
}

cv::Mat decode_raw_image(const std::string& encoding, std::uint32_t width, std::uint32_t height, std::uint32_t step,
                         bool big_endian, const std::uint8_t* data, std::size_t size, const std::string& where) {
  const int bpp = raw_bytes_per_pixel(encoding);
  if (bpp == 0)
    throw InputError(where + ": image encoding '" + encoding +
                     "' is not supported (rgb8, bgr8, rgba8, bgra8, mono8, 16UC1, mono16, 32FC1)");
  if (width == 0 || height == 0 || width > 100000 || height > 100000)
    throw InputError(where + ": image of " + std::to_string(width) + "x" + std::to_string(height) + " pixels");
  const std::size_t row = static_cast<std::size_t>(width) * static_cast<std::size_t>(bpp);
  if (step < row || static_cast<std::size_t>(step) * height > size)
    throw InputError(where + ": " + encoding + " image of " + std::to_string(width) + "x" + std::to_string(height) +
                     " with step " + std::to_string(step) + " needs " +
                     std::to_string(static_cast<std::size_t>(step) * height) + " bytes, the message holds " +
                     std::to_string(size));
  const int type = bpp == 3                          ? CV_8UC3
                   : bpp == 4 && encoding != "32FC1" ? CV_8UC4
                   : bpp == 1                        ? CV_8UC1
                   : bpp == 2                        ? CV_16UC1
                                                     : CV_32FC1;
  // The message's bytes as a matrix, without a copy. A step that is not a multiple of the element size (legal in a
  // message) cannot be an OpenCV matrix step (found by fuzzing): such rows are copied one by one.
  const std::size_t element = static_cast<std::size_t>(CV_ELEM_SIZE1(type));
  cv::Mat view;
  if (step % element == 0) {
    view = cv::Mat(static_cast<int>(height), static_cast<int>(width), type, const_cast<std::uint8_t*>(data), step);
  } else {
    view.create(static_cast<int>(height), static_cast<int>(width), type);
    for (std::uint32_t y = 0; y < height; ++y)
      std::memcpy(view.ptr(static_cast<int>(y)), data + static_cast<std::size_t>(step) * y, row);
  }
  cv::Mat out;
  if (encoding == "rgb8") {
    cv::cvtColor(view, out, cv::COLOR_RGB2BGR);
  } else if (encoding == "rgba8") {
    cv::cvtColor(view, out, cv::COLOR_RGBA2BGR);
  } else if (encoding == "bgra8" || encoding == "8UC4") {
    cv::cvtColor(view, out, cv::COLOR_BGRA2BGR);
  } else {
    out = view.clone();  // owns its data: the message's buffer goes with the message
  }
  if (big_endian && (bpp == 2 || type == CV_32FC1)) {
    for (int y = 0; y < out.rows; ++y) {
      auto* p = out.ptr<std::uint8_t>(y);
      for (int x = 0; x < out.cols; ++x, p += bpp) std::reverse(p, p + bpp);
    }
  }
  return out;
}

bool is_compressed_depth(const std::string& format) { return format.find("compressedDepth") != std::string::npos; }

cv::Mat decode_compressed_image(const std::string& format, const std::uint8_t* data, std::size_t size,
                                const std::string& where) {
  if (!is_compressed_depth(format)) {
    if (!is_png({data, size}) && !is_jpeg({data, size}))
      throw InputError(where + ": compressed image (format '" + format + "') is not PNG or JPEG data");
    cv::Mat bgr = decode_colour_image({data, size});
    if (bgr.empty()) throw InputError(where + ": cannot decode the compressed image (format '" + format + "')");
    return bgr;
  }
  // image_transport's compressedDepth: a 12-byte header, then a PNG (older writers: the PNG alone).
  std::size_t offset = 0;
  float quant_a = 0, quant_b = 0;
  if (!is_png({data, size})) {
    if (size < kCompressedDepthHeader || !is_png({data + kCompressedDepthHeader, size - kCompressedDepthHeader}))
      throw InputError(where + ": compressedDepth data (format '" + format + "') holds no PNG");
    std::memcpy(&quant_a, data + 4, sizeof(float));
    std::memcpy(&quant_b, data + 8, sizeof(float));
    offset = kCompressedDepthHeader;
  }
  cv::Mat raw = decode_unchanged_image({data + offset, size - offset});
  if (raw.empty() || raw.type() != CV_16UC1)
    throw InputError(where + ": compressedDepth PNG (format '" + format + "') is not a 16-bit single-channel image");
  if (format.rfind("16UC1", 0) == 0 || format.rfind("mono16", 0) == 0) return raw;
  if (format.rfind("32FC1", 0) != 0)
    throw InputError(where + ": compressedDepth format '" + format + "' names no depth type (16UC1 or 32FC1)");
  if (!(quant_a > 0)) throw InputError(where + ": 32FC1 compressedDepth without its quantisation parameters");
  // Inverse-depth quantisation: v = quant_a / z + quant_b.
  cv::Mat metres(raw.size(), CV_32FC1);
  for (int y = 0; y < raw.rows; ++y) {
    const auto* s = raw.ptr<std::uint16_t>(y);
    auto* m = metres.ptr<float>(y);
    for (int x = 0; x < raw.cols; ++x) {
      const float v = static_cast<float>(s[x]) - quant_b;
      m[x] = (s[x] == 0 || v <= 0) ? 0.0f : quant_a / v;
    }
  }
  return metres;
}

std::vector<std::uint8_t> encode_compressed_depth(const cv::Mat& depth16) {
  CV_Assert(depth16.type() == CV_16UC1);
  std::vector<std::uint8_t> png;
  cv::imencode(".png", depth16, png);
  std::vector<std::uint8_t> out(kCompressedDepthHeader + png.size(), 0);
  std::copy(png.begin(), png.end(), out.begin() + static_cast<std::ptrdiff_t>(kCompressedDepthHeader));
  return out;
}

}  // namespace varslam::ros_image
