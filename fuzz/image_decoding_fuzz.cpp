// The image decoders' fast paths against cv::imdecode: whatever a fast path decodes must be exactly what OpenCV
// decodes from the same bytes. The first input byte picks the path (even: 16-bit PNG, odd: JPEG); for the PNG the
// harness rewrites every chunk's CRC first, so that mutations reach the inflate and the unfiltering instead of
// stopping at the checksum.
#include <zlib.h>

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "fuzz_input.hpp"
#include "io/image_decoding.hpp"

namespace {

std::uint32_t be32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} << 24 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[2]} << 8 | std::uint32_t{p[3]};
}

void fix_chunk_crcs(std::vector<std::uint8_t>& png) {
  std::size_t pos = 8;
  while (png.size() >= 12 && pos <= png.size() - 12) {
    const std::size_t length = be32(&png[pos]);
    if (length > png.size() - pos - 12) return;
    const auto crc = static_cast<std::uint32_t>(crc32(0, &png[pos + 4], static_cast<uInt>(length + 4)));
    for (int k = 0; k < 4; ++k) png[pos + 8 + length + std::size_t(k)] = static_cast<std::uint8_t>(crc >> (24 - 8 * k));
    pos += 12 + length;
  }
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  std::vector<std::uint8_t> bytes(data + 1, data + size);
  const bool jpeg = data[0] & 1;
  if (!jpeg) fix_chunk_crcs(bytes);
  const std::optional<cv::Mat> ours =
      jpeg ? varslam::decode_ycbcr_jpeg_to_bgr(bytes) : varslam::decode_grey16_png(bytes);
  // The whole decoders never throw, crash or allocate much for a damaged header (libFuzzer's memory limit).
  (void)(jpeg ? varslam::decode_colour_image(bytes) : varslam::decode_unchanged_image(bytes));
  if (!ours) return 0;
  // OpenCV on its own only where the fast path has read the header's size as plausible: it allocates whatever a
  // damaged header declares. Where both give an image it must be the same; the fast path may read a damaged
  // stream OpenCV refuses (libdeflate accepts reserved deflate codes that zlib rejects).
  cv::Mat theirs;
  try {
    theirs = cv::imdecode(bytes, jpeg ? cv::IMREAD_COLOR : cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {  // OpenCV refuses some headers by throwing (a size over its pixel limit)
  }
  if (!theirs.empty()) VARSLAM_FUZZ_EXPECT(same(*ours, theirs));
  return 0;
}
