#include "io/image_decoding.hpp"

#include <libdeflate.h>
#include <turbojpeg.h>

#include <algorithm>
#include <cstdlib>
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

enum class JpegWalkEnd { StartOfScan, Stopped, Broken };

// Calls visit(marker, payload) for each marker segment before the start of scan, skipping what libjpeg's marker
// reader skips (stray bytes, fill bytes, stuffed zeros), so that it sees the segments OpenCV's decoder will see.
// visit returns false to stop the walk.
template <class Visit>
JpegWalkEnd walk_jpeg_segments(std::span<const std::uint8_t> b, Visit visit) {
  std::size_t pos = 2;  // after SOI
  while (pos + 2 <= b.size()) {
    const std::uint8_t marker = b[pos + 1];
    if (b[pos] != 0xFF || marker == 0xFF || marker == 0x00) {
      ++pos;
      continue;
    }
    if (marker == 0xDA) return JpegWalkEnd::StartOfScan;
    if (marker == 0xD9) return JpegWalkEnd::Broken;  // end of image before any scan
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) {  // markers without a length
      pos += 2;
      continue;
    }
    if (pos + 4 > b.size()) return JpegWalkEnd::Broken;
    const std::size_t length = read_be16(&b[pos + 2]);
    if (length < 2 || length > b.size() - pos - 2) return JpegWalkEnd::Broken;
    if (!visit(marker, b.subspan(pos + 4, length - 2))) return JpegWalkEnd::Stopped;
    pos += 2 + length;
  }
  return JpegWalkEnd::Broken;
}

// cv::imdecode reads EXIF from the first APP1 segment whatever its label, and turns the image by its orientation
// tag: a JPEG with any APP1 segment (or whose segments cannot be walked to the scan) is left to it.
bool jpeg_may_carry_exif(std::span<const std::uint8_t> b) {
  bool app1 = false;
  const JpegWalkEnd end = walk_jpeg_segments(b, [&](std::uint8_t marker, std::span<const std::uint8_t>) {
    app1 = marker == 0xE1;
    return !app1;
  });
  return app1 || end != JpegWalkEnd::StartOfScan;
}

// The size in the JPEG's frame header (SOF0-SOF15; C4, C8 and CC are other markers).
std::optional<cv::Size> jpeg_declared_size(std::span<const std::uint8_t> b) {
  std::optional<cv::Size> size;
  walk_jpeg_segments(b, [&](std::uint8_t m, std::span<const std::uint8_t> payload) {
    const bool frame_header = m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC;
    if (frame_header && payload.size() >= 5)  // precision, then height and width
      size = cv::Size(static_cast<int>(read_be16(&payload[3])), static_cast<int>(read_be16(&payload[1])));
    return !size;
  });
  return size;
}

struct TurboJpegDeleter {
  void operator()(void* handle) const { tjDestroy(handle); }
};

// ---- PNG ----

constexpr std::size_t kMaxDeflateRatio = 1032;  // the most a deflate stream can expand (258 bytes per 2 bits)

bool is_chunk_name(const std::uint8_t* type) {
  return std::all_of(type, type + 4, [](std::uint8_t c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); });
}

// The fewest bytes the pixel data of a PNG with this header can inflate to: each row's filter byte and its
// pixels at the header's bit depth and colour type (a palette or unknown type counted at one channel).
std::int64_t png_min_raw_bytes(std::span<const std::uint8_t> b) {
  const std::int64_t width = read_be32(&b[16]), height = read_be32(&b[20]);
  const int bit_depth = b[24], colour_type = b[25];
  const int channels = colour_type == 2 ? 3 : colour_type == 4 ? 2 : colour_type == 6 ? 4 : 1;
  return height * (1 + (width * bit_depth * channels + 7) / 8);
}

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

struct Grey16Png {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> compressed;
};

// The size and concatenated IDAT data of a non-interlaced 16-bit greyscale PNG whose chunks all check out;
// std::nullopt for any other kind, a damaged chunk, or a chunk whose meaning the fast path does not apply
// (tRNS, or an unknown critical chunk).
std::optional<Grey16Png> parse_grey16_png(std::span<const std::uint8_t> b) {
  if (!is_png(b)) return std::nullopt;
  Grey16Png png;
  bool have_header = false, idat_seen = false, idat_ended = false;
  std::size_t pos = 8;
  while (b.size() - pos >= 12) {
    const std::size_t length = read_be32(&b[pos]);
    if (length > b.size() - pos - 12) return std::nullopt;
    const std::uint8_t* type = &b[pos + 4];
    const std::uint8_t* data = type + 4;
    if (!is_chunk_name(type) || libdeflate_crc32(0, type, length + 4) != read_be32(data + length))
      return std::nullopt;
    const std::string_view name(reinterpret_cast<const char*>(type), 4);
    pos += 12 + length;
    if (!have_header) {
      if (name != "IHDR" || length != 13) return std::nullopt;
      png.width = read_be32(data);
      png.height = read_be32(data + 4);
      const bool grey16 = data[8] == 16 && data[9] == 0 && data[10] == 0 && data[11] == 0 && data[12] == 0;
      // The sides are checked before their product, which then cannot overflow.
      const std::int64_t width = png.width, height = png.height;
      if (!grey16 || width == 0 || height == 0 || width > kMaxDecodedPixels || height > kMaxDecodedPixels ||
          width * height > kMaxDecodedPixels)
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

// The zlib stream inflated to exactly `size` bytes; std::nullopt when it holds anything else. A window smaller
// than the data is left to zlib (through OpenCV), which enforces it where libdeflate does not.
std::optional<std::vector<std::uint8_t>> inflate_exactly(const std::vector<std::uint8_t>& zlib, std::size_t size) {
  // Deflate expands at most 1032 times: a header promising more than the data can hold is damaged, and must not
  // make a small file allocate a large buffer.
  if (zlib.size() < 2 || size / kMaxDeflateRatio > zlib.size()) return std::nullopt;
  const int window_log2 = (zlib[0] >> 4) + 8;  // 15 (32 KB) is the most deflate's distances can reach anyway
  if (window_log2 < 15 && size > std::size_t{1} << window_log2) return std::nullopt;
  std::vector<std::uint8_t> raw(size);
  const std::unique_ptr<libdeflate_decompressor, DeflateDeleter> inflater(libdeflate_alloc_decompressor());
  std::size_t produced = 0;
  if (!inflater ||
      libdeflate_zlib_decompress(inflater.get(), zlib.data(), zlib.size(), raw.data(), size, &produced) !=
          LIBDEFLATE_SUCCESS ||
      produced != size)
    return std::nullopt;
  return raw;
}

// Whether OpenCV may be given the file: it allocates the image its header declares before reading any pixel, so
// a damaged header of a few bytes could cost gigabytes. Refused: more pixels than any camera image has, or a PNG
// whose smallest possible pixel data is more than its bytes can inflate to.
bool plausible_size(std::span<const std::uint8_t> b) {
  if (is_png(b)) {
    if (b.size() < 26) return true;  // no header: OpenCV allocates nothing
    const std::int64_t width = read_be32(&b[16]), height = read_be32(&b[20]);
    return width <= kMaxDecodedPixels && height <= kMaxDecodedPixels && width * height <= kMaxDecodedPixels &&
           png_min_raw_bytes(b) / std::int64_t{kMaxDeflateRatio} <= static_cast<std::int64_t>(b.size());
  }
  const std::optional<cv::Size> size = jpeg_declared_size(b);
  return !size || std::int64_t{size->width} * size->height <= kMaxDecodedPixels;
}

cv::Mat opencv_decode(std::span<const std::uint8_t> bytes, int flags) {
  if (!is_png_or_jpeg_file(bytes) || bytes.size() > std::size_t{std::numeric_limits<int>::max()} ||
      !plausible_size(bytes))
    return {};
  const cv::Mat wrapped(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<std::uint8_t*>(bytes.data()));
  try {
    return cv::imdecode(wrapped, flags);  // reads only
  } catch (const std::exception&) {
    return {};  // OpenCV throws for some damaged headers (a size over its pixel limit): no image, as for others
  }
}

}  // namespace

bool is_png(std::span<const std::uint8_t> bytes) {
  static constexpr std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  return bytes.size() >= 8 && std::equal(std::begin(kSignature), std::end(kSignature), bytes.begin());
}

bool is_jpeg(std::span<const std::uint8_t> bytes) {
  return bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
}

bool is_png_or_jpeg_file(std::span<const std::uint8_t> bytes) {
  const bool dicom = bytes.size() >= 132 && std::memcmp(bytes.data() + 128, "DICM", 4) == 0;
  return (is_png(bytes) || is_jpeg(bytes)) && !dicom;
}

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
  if (!is_jpeg(bytes) || jpeg_may_carry_exif(bytes)) return std::nullopt;
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
  // The accurate inverse DCT and smooth chroma upsampling are TurboJPEG's defaults, and libjpeg's that OpenCV
  // decodes with. At the first warning (a damaged stream) the file is left to OpenCV, which decides what it gives.
  if (tjDecompress2(handle.get(), data, size, bgr.data, width, static_cast<int>(bgr.step[0]), height, TJPF_BGR,
                    TJFLAG_STOPONWARNING) != 0)
    return std::nullopt;
  return bgr;
}

std::optional<cv::Mat> decode_grey16_png(std::span<const std::uint8_t> bytes) {
  const std::optional<Grey16Png> png = parse_grey16_png(bytes);
  if (!png) return std::nullopt;
  const std::size_t row_bytes = std::size_t{png->width} * 2;
  // Each row starts with its filter type.
  std::optional<std::vector<std::uint8_t>> raw = inflate_exactly(png->compressed, png->height * (row_bytes + 1));
  if (!raw) return std::nullopt;
  cv::Mat image(static_cast<int>(png->height), static_cast<int>(png->width), CV_16UC1);
  const std::vector<std::uint8_t> zero_row(row_bytes, 0);
  const std::uint8_t* prev = zero_row.data();
  for (int y = 0; y < image.rows; ++y) {
    std::uint8_t* row = raw->data() + std::size_t(y) * (row_bytes + 1);
    if (!unfilter_row(row[0], row + 1, prev, row_bytes)) return std::nullopt;
    prev = row + 1;
    auto* out = image.ptr<std::uint16_t>(y);
    for (int x = 0; x < image.cols; ++x) out[x] = static_cast<std::uint16_t>(read_be16(prev + 2 * std::size_t(x)));
  }
  return image;
}

cv::Mat decode_colour_image(std::span<const std::uint8_t> bytes) {
  try {
    if (std::optional<cv::Mat> bgr = decode_ycbcr_jpeg_to_bgr(bytes)) return *bgr;
  } catch (const std::exception&) {  // out of memory for a large image: OpenCV may still manage, or say no
  }
  return opencv_decode(bytes, cv::IMREAD_COLOR);
}

cv::Mat decode_unchanged_image(std::span<const std::uint8_t> bytes) {
  try {
    if (std::optional<cv::Mat> grey16 = decode_grey16_png(bytes)) return *grey16;
  } catch (const std::exception&) {  // out of memory for a large image: OpenCV may still manage, or say no
  }
  return opencv_decode(bytes, cv::IMREAD_UNCHANGED);
}

}  // namespace varslam
