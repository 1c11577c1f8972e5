#include "io/image_decoding.hpp"

#include <libdeflate.h>
#include <turbojpeg.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <string_view>

namespace varslam {
namespace {

std::uint32_t read_be32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} << 24 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[2]} << 8 | std::uint32_t{p[3]};
}

std::uint32_t read_be16(const std::uint8_t* p) { return std::uint32_t{p[0]} << 8 | std::uint32_t{p[1]}; }

// Far beyond any camera's image (8192 x 8192): a header declaring more is damaged, or no frame of a dataset.
constexpr std::int64_t kMaxDecodedPixels = std::int64_t{1} << 26;

// ---- JPEG ----

// cv::imdecode turns an image by its EXIF orientation tag, so a JPEG that carries EXIF (or whose segments
// before the scan cannot be walked) is left to it. Walks the marker segments up to the start of scan.
bool jpeg_may_carry_exif(std::span<const std::uint8_t> b) {
  std::size_t pos = 2;  // after SOI
  while (pos + 4 <= b.size()) {
    if (b[pos] != 0xFF) return true;
    const std::uint8_t marker = b[pos + 1];
    if (marker == 0xFF) {  // fill byte
      ++pos;
      continue;
    }
    if (marker == 0xDA) return false;  // start of scan: no EXIF before it
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // markers without a length
      pos += 2;
      continue;
    }
    const std::size_t length = read_be16(&b[pos + 2]);
    if (length < 2 || pos + 2 + length > b.size()) return true;
    if (marker == 0xE1 && length >= 8 && std::memcmp(&b[pos + 4], "Exif\0\0", 6) == 0) return true;
    pos += 2 + length;
  }
  return true;
}


struct TurboJpegDeleter {
  void operator()(void* handle) const { tjDestroy(handle); }
};

// ---- PNG ----

constexpr std::uint8_t kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
constexpr std::uint32_t kMaxPngSide = 1u << 14;  // larger images are left to OpenCV's own limits
constexpr std::size_t kMaxDeflateRatio = 1032;    // the most a deflate stream can expand (258 bytes per 2 bits)

// A row of `n` bytes of a PNG with two bytes per pixel, unfiltered in place (PNG specification, "Filter
// algorithms"); `prev` is the row above, already unfiltered (zeros above the first row). False for an unknown
// filter type. The first pixel has no left neighbour, so its bytes are done apart from the loops, which then
// carry no test.
bool unfilter_row(std::uint8_t type, std::uint8_t* cur, const std::uint8_t* prev, std::size_t n) {
  constexpr std::size_t bpp = 2;
  switch (type) {
    case 0:
      return true;
    case 1:
      for (std::size_t i = bpp; i < n; ++i) cur[i] = std::uint8_t(cur[i] + cur[i - bpp]);
      return true;
    case 2:
      for (std::size_t i = 0; i < n; ++i) cur[i] = std::uint8_t(cur[i] + prev[i]);
      return true;
    case 3:
      for (std::size_t i = 0; i < bpp; ++i) cur[i] = std::uint8_t(cur[i] + (prev[i] >> 1));
      for (std::size_t i = bpp; i < n; ++i) cur[i] = std::uint8_t(cur[i] + ((cur[i - bpp] + prev[i]) >> 1));
      return true;
    case 4: {
      // Each byte lane's left and up-left values stay in registers: the loop's chain of dependent steps is what
      // bounds its speed, and going through memory for the left neighbour would lengthen it.
      int left[bpp] = {0, 0}, up_left[bpp] = {0, 0};  // zeros at the row's start
      for (std::size_t i = 0; i < n; i += bpp)
        for (std::size_t k = 0; k < bpp; ++k) {
          const int a = left[k], b = prev[i + k], c = up_left[k];
          const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
          const int predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
          left[k] = cur[i + k] = std::uint8_t(cur[i + k] + predictor);
          up_left[k] = b;
        }
      return true;
    }
    default:
      return false;
  }
}

struct DeflateDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

// The concatenated IDAT data of a non-interlaced 16-bit greyscale PNG whose chunks all check out, and its size;
// std::nullopt for any other kind, a damaged chunk, or a chunk whose meaning the fast path does not apply
// (tRNS, or an unknown critical chunk).
struct Grey16Png {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> compressed;
};

std::optional<Grey16Png> parse_grey16_png(std::span<const std::uint8_t> b) {
  if (b.size() < 8 || !std::equal(std::begin(kPngSignature), std::end(kPngSignature), b.begin())) return std::nullopt;
  Grey16Png png;
  bool have_header = false, idat_seen = false, idat_ended = false;
  std::size_t pos = 8;
  while (b.size() - pos >= 12) {
    const std::size_t length = read_be32(&b[pos]);
    if (length > b.size() - pos - 12) return std::nullopt;
    const std::uint8_t* type = &b[pos + 4];
    const std::uint8_t* data = type + 4;
    if (libdeflate_crc32(0, type, length + 4) != read_be32(data + length)) return std::nullopt;
    const std::string_view name(reinterpret_cast<const char*>(type), 4);
    pos += 12 + length;
    if (!have_header) {
      if (name != "IHDR" || length != 13) return std::nullopt;
      png.width = read_be32(data);
      png.height = read_be32(data + 4);
      const bool grey16 = data[8] == 16 && data[9] == 0 && data[10] == 0 && data[11] == 0 && data[12] == 0;
      if (!grey16 || png.width == 0 || png.height == 0 || png.width > kMaxPngSide || png.height > kMaxPngSide)
        return std::nullopt;
      have_header = true;
    } else if (name == "IDAT") {
      if (idat_ended) return std::nullopt;
      idat_seen = true;
      png.compressed.insert(png.compressed.end(), data, data + length);
    } else if (name == "IEND") {
      return idat_seen ? std::optional(std::move(png)) : std::nullopt;
    } else {
      idat_ended = idat_seen;
      const bool critical = type[0] >= 'A' && type[0] <= 'Z';
      if (critical || name == "tRNS") return std::nullopt;
    }
  }
  return std::nullopt;  // no IEND
}

// The width and height a PNG's or JPEG's header declares; std::nullopt when the header cannot be found.
std::optional<cv::Size> declared_size(std::span<const std::uint8_t> b) {
  if (b.size() >= 24 && std::equal(std::begin(kPngSignature), std::end(kPngSignature), b.begin()))
    return cv::Size(static_cast<int>(std::min<std::uint32_t>(read_be32(&b[16]), 1u << 30)),
                    static_cast<int>(std::min<std::uint32_t>(read_be32(&b[20]), 1u << 30)));
  if (b.size() < 4 || b[0] != 0xFF || b[1] != 0xD8) return std::nullopt;
  for (std::size_t pos = 2; pos + 9 <= b.size();) {  // the JPEG's segments up to its frame header (SOFn)
    if (b[pos] != 0xFF) return std::nullopt;
    const std::uint8_t marker = b[pos + 1];
    if (marker == 0xFF || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // fill byte, no length
      pos += marker == 0xFF ? 1 : 2;
      continue;
    }
    const bool frame_header = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (frame_header)  // precision, then height and width
      return cv::Size(static_cast<int>(read_be16(&b[pos + 7])), static_cast<int>(read_be16(&b[pos + 5])));
    pos += 2 + read_be16(&b[pos + 2]);
  }
  return std::nullopt;
}

// Whether OpenCV may be given the file: it allocates the image its header declares before reading any pixel, so
// a damaged header of a few bytes could cost gigabytes. Refused: more pixels than any camera image has, or a PNG
// whose smallest possible pixel data (one bit a pixel) is more than its bytes can inflate to.
bool plausible_size(std::span<const std::uint8_t> b) {
  const std::optional<cv::Size> size = declared_size(b);
  if (!size) return true;  // OpenCV finds no header either, and allocates nothing
  const std::int64_t pixels = std::int64_t{size->width} * size->height;
  if (pixels > kMaxDecodedPixels) return false;
  const bool png = b[0] == kPngSignature[0];
  const std::int64_t min_png_bytes = std::int64_t{size->height} * (1 + (std::int64_t{size->width} + 7) / 8);
  return !png || min_png_bytes / std::int64_t{kMaxDeflateRatio} <= static_cast<std::int64_t>(b.size());
}

cv::Mat opencv_decode(std::span<const std::uint8_t> bytes, int flags) {
  if (bytes.empty() || bytes.size() > std::size_t{std::numeric_limits<int>::max()} || !plausible_size(bytes))
    return {};
  const cv::Mat wrapped(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<std::uint8_t*>(bytes.data()));
  try {
    return cv::imdecode(wrapped, flags);  // reads only
  } catch (const cv::Exception&) {
    return {};  // OpenCV throws for some damaged headers (a size over its pixel limit): no image, as for others
  }
}

}  // namespace

std::optional<std::vector<std::uint8_t>> read_file_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) return std::nullopt;
  const std::streamoff size = in.tellg();
  if (size < 0) return std::nullopt;
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), size)) return std::nullopt;
  return bytes;
}

std::optional<cv::Mat> decode_ycbcr_jpeg_to_bgr(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 4 || bytes[0] != 0xFF || bytes[1] != 0xD8 || jpeg_may_carry_exif(bytes)) return std::nullopt;
  const std::unique_ptr<void, TurboJpegDeleter> handle(tjInitDecompress());
  if (!handle) return std::nullopt;
  int width = 0, height = 0, subsampling = 0, colourspace = 0;
  auto* data = const_cast<unsigned char*>(bytes.data());  // TurboJPEG 2.1 takes a non-const pointer; it only reads
  const auto size = static_cast<unsigned long>(bytes.size());
  if (tjDecompressHeader3(handle.get(), data, size, &width, &height, &subsampling, &colourspace) != 0 ||
      colourspace != TJCS_YCbCr || width <= 0 || height <= 0 ||
      std::int64_t{width} * height > kMaxDecodedPixels)  // a damaged header must not allocate gigabytes here
    return std::nullopt;
  cv::Mat bgr(height, width, CV_8UC3);
  // Flags 0: the accurate inverse DCT and smooth chroma upsampling, libjpeg's defaults that OpenCV decodes with.
  // Any warning (a damaged stream) is left to OpenCV, which decides what such a file gives.
  if (tjDecompress2(handle.get(), data, size, bgr.data, width, static_cast<int>(bgr.step[0]), height, TJPF_BGR, 0) != 0)
    return std::nullopt;
  return bgr;
}

std::optional<cv::Mat> decode_grey16_png(std::span<const std::uint8_t> bytes) {
  const std::optional<Grey16Png> png = parse_grey16_png(bytes);
  if (!png) return std::nullopt;
  const std::size_t row_bytes = std::size_t{png->width} * 2;
  const std::size_t raw_size = std::size_t{png->height} * (row_bytes + 1);  // each row starts with its filter type
  // Deflate expands at most 1032 times: a header promising more than the data can hold is damaged, and must not
  // make a small file allocate a large buffer.
  if (raw_size / kMaxDeflateRatio > png->compressed.size()) return std::nullopt;
  std::vector<std::uint8_t> raw(raw_size);
  const std::unique_ptr<libdeflate_decompressor, DeflateDeleter> inflater(libdeflate_alloc_decompressor());
  if (!inflater) return std::nullopt;
  std::size_t produced = 0;
  if (libdeflate_zlib_decompress(inflater.get(), png->compressed.data(), png->compressed.size(), raw.data(),
                                 raw_size, &produced) != LIBDEFLATE_SUCCESS ||
      produced != raw_size)
    return std::nullopt;
  cv::Mat image(static_cast<int>(png->height), static_cast<int>(png->width), CV_16UC1);
  const std::vector<std::uint8_t> zero_row(row_bytes, 0);
  const std::uint8_t* prev = zero_row.data();
  for (int y = 0; y < image.rows; ++y) {
    std::uint8_t* row = raw.data() + std::size_t(y) * (row_bytes + 1);
    if (!unfilter_row(row[0], row + 1, prev, row_bytes)) return std::nullopt;
    prev = row + 1;
    auto* out = image.ptr<std::uint16_t>(y);
    for (int x = 0; x < image.cols; ++x) out[x] = static_cast<std::uint16_t>(read_be16(prev + 2 * std::size_t(x)));
  }
  return image;
}

cv::Mat decode_colour_image(std::span<const std::uint8_t> bytes) {
  if (std::optional<cv::Mat> bgr = decode_ycbcr_jpeg_to_bgr(bytes)) return *bgr;
  return opencv_decode(bytes, cv::IMREAD_COLOR);
}

cv::Mat decode_unchanged_image(std::span<const std::uint8_t> bytes) {
  if (std::optional<cv::Mat> grey16 = decode_grey16_png(bytes)) return *grey16;
  return opencv_decode(bytes, cv::IMREAD_UNCHANGED);
}

}  // namespace varslam
