// ROS image messages as a bag or a topic delivers them: the first input byte picks raw or compressed and the
// encoding, the next bytes the raw image's size, step and endianness, the rest is the pixel data. An image is
// decoded or refused with InputError; what decodes has the size and type its encoding promises.
#include <array>
#include <string>

#include "core/error.hpp"
#include "fuzz_input.hpp"
#include "io/ros_image_codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace varslam;
  static const std::array<const char*, 8> kRaw = {"rgb8",  "bgr8",   "rgba8", "mono8",
                                                  "16UC1", "mono16", "32FC1", "yuv422"};
  static const std::array<const char*, 4> kCompressed = {"jpeg", "bgr8; png compressed bgr8",
                                                         "16UC1; compressedDepth png", "32FC1; compressedDepth"};
  if (size < 4) return 0;
  const bool compressed = data[0] & 0x80;
  cv::Mat m;
  try {
    if (compressed) {
      const std::string format = kCompressed[data[0] % kCompressed.size()];
      m = ros_image::decode_compressed_image(format, data + 1, size - 1, "fuzz");
      VARSLAM_FUZZ_EXPECT(!m.empty());
      VARSLAM_FUZZ_EXPECT(ros_image::is_compressed_depth(format) ? (m.type() == CV_16UC1 || m.type() == CV_32FC1)
                                                                 : m.type() == CV_8UC3);
    } else {
      const std::string encoding = kRaw[data[0] % kRaw.size()];
      const std::uint32_t width = data[1] % 17, height = data[2] % 13, step = data[3];
      m = ros_image::decode_raw_image(encoding, width, height, step, data[0] & 0x40, data + 4, size - 4, "fuzz");
      VARSLAM_FUZZ_EXPECT(m.cols == static_cast<int>(width) && m.rows == static_cast<int>(height));
      VARSLAM_FUZZ_EXPECT(m.elemSize() == static_cast<std::size_t>(ros_image::raw_bytes_per_pixel(encoding)) ||
                          m.type() == CV_8UC3);
    }
  } catch (const InputError&) {
    return 0;
  }
  return 0;
}
