// The image decoders' fast paths give cv::imdecode's pixels, and leave to it every file they do not handle.
#include "io/image_decoding.hpp"

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

namespace varslam {
namespace {

using Bytes = std::vector<std::uint8_t>;

cv::Mat opencv(const Bytes& bytes, int flags) { return cv::imdecode(bytes, flags); }

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && (a.empty() || cv::norm(a, b, cv::NORM_INF) == 0.0);
}

// A 16-bit image with smooth stretches, steps and noise, so that every PNG filter meets real work.
cv::Mat depth_like(int rows, int cols, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat m(rows, cols, CV_16UC1);
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x)
      m.at<std::uint16_t>(y, x) = static_cast<std::uint16_t>((x * 37 + y * 11 + (x > cols / 2 ? 20000 : 0) +
                                                               rng.uniform(0, 300)) % 65536);
  m.at<std::uint16_t>(0, 0) = 65535;
  return m;
}

// ---- PNG files built byte by byte, so each filter type and each chunk layout is chosen, not left to libpng ----

void put_be32(Bytes& out, std::uint32_t v) {
  for (int shift : {24, 16, 8, 0}) out.push_back(static_cast<std::uint8_t>(v >> shift));
}

void put_chunk(Bytes& png, const std::string& type, const Bytes& data) {
  put_be32(png, static_cast<std::uint32_t>(data.size()));
  Bytes body(type.begin(), type.end());
  body.insert(body.end(), data.begin(), data.end());
  png.insert(png.end(), body.begin(), body.end());
  put_be32(png, static_cast<std::uint32_t>(crc32(0, body.data(), static_cast<uInt>(body.size()))));
}

int paeth(int a, int b, int c) {
  const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

struct PngLayout {
  std::vector<int> filters = {0, 1, 2, 3, 4};  // row y uses filters[y % size]
  std::size_t idat_pieces = 1;
  int bit_depth = 16, colour_type = 0, interlace = 0;
  int window_bits = 15;  // zlib's window: 2^window_bits bytes
  std::vector<std::pair<std::string, Bytes>> extra_chunks;  // after IHDR
};

// The PNG of a CV_16UC1 image, filtered row by row as `layout` says (the encoder's side of the specification).
Bytes make_png(const cv::Mat& image, const PngLayout& layout) {
  const std::size_t row_bytes = std::size_t(image.cols) * 2;
  Bytes raw, previous(row_bytes, 0);
  for (int y = 0; y < image.rows; ++y) {
    Bytes row(row_bytes);
    for (int x = 0; x < image.cols; ++x) {
      const std::uint16_t v = image.at<std::uint16_t>(y, x);
      row[2 * std::size_t(x)] = static_cast<std::uint8_t>(v >> 8);
      row[2 * std::size_t(x) + 1] = static_cast<std::uint8_t>(v & 0xFF);
    }
    const int filter = layout.filters[std::size_t(y) % layout.filters.size()];
    raw.push_back(static_cast<std::uint8_t>(filter));
    for (std::size_t i = 0; i < row_bytes; ++i) {
      const int a = i >= 2 ? row[i - 2] : 0, b = previous[i], c = i >= 2 ? previous[i - 2] : 0;
      const int predictor = filter == 1   ? a
                            : filter == 2 ? b
                            : filter == 3 ? (a + b) / 2
                            : filter == 4 ? paeth(a, b, c)
                                          : 0;
      raw.push_back(static_cast<std::uint8_t>(row[i] - predictor));
    }
    previous = row;
  }
  Bytes packed(compressBound(static_cast<uLong>(raw.size())) + 64);
  z_stream z{};
  EXPECT_EQ(deflateInit2(&z, 6, Z_DEFLATED, layout.window_bits, 8, Z_DEFAULT_STRATEGY), Z_OK);
  z.next_in = raw.data();
  z.avail_in = static_cast<uInt>(raw.size());
  z.next_out = packed.data();
  z.avail_out = static_cast<uInt>(packed.size());
  EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
  packed.resize(z.total_out);
  deflateEnd(&z);

  Bytes png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  Bytes header;
  put_be32(header, static_cast<std::uint32_t>(image.cols));
  put_be32(header, static_cast<std::uint32_t>(image.rows));
  for (int v : {layout.bit_depth, layout.colour_type, 0, 0, layout.interlace}) header.push_back(std::uint8_t(v));
  put_chunk(png, "IHDR", header);
  for (const auto& [type, data] : layout.extra_chunks) put_chunk(png, type, data);
  const std::size_t piece = packed.size() / layout.idat_pieces + 1;
  for (std::size_t at = 0; at < packed.size(); at += piece)
    put_chunk(png, "IDAT", Bytes(packed.begin() + std::ptrdiff_t(at),
                                 packed.begin() + std::ptrdiff_t(std::min(packed.size(), at + piece))));
  put_chunk(png, "IEND", {});
  return png;
}

TEST(ImageDecoding, Grey16PngGivesOpenCvsPixelsForEveryFilterAndSize) {
  // The last is more data (38 KB) than deflate's largest window.
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(63, 17), cv::Size(640, 30)})
    for (const int filter : {0, 1, 2, 3, 4}) {
      const cv::Mat image = depth_like(size.height, size.width, 7 + std::uint64_t(filter));
      PngLayout layout;
      layout.filters = {filter};
      const Bytes png = make_png(image, layout);
      const std::optional<cv::Mat> ours = decode_grey16_png(png);
      ASSERT_TRUE(ours) << "filter " << filter << " size " << size;
      EXPECT_TRUE(same(*ours, image)) << "filter " << filter << " size " << size;
      EXPECT_TRUE(same(*ours, opencv(png, cv::IMREAD_UNCHANGED))) << "filter " << filter << " size " << size;
    }
}

TEST(ImageDecoding, Grey16PngWithMixedFiltersSplitDataAndTextChunksDecodes) {
  const cv::Mat image = depth_like(40, 33, 3);
  PngLayout layout;
  layout.filters = {4, 0, 3, 1, 2, 4, 4};
  layout.idat_pieces = 5;
  layout.extra_chunks = {{"tEXt", Bytes{'k', 0, 'v'}}};
  const Bytes png = make_png(image, layout);
  const std::optional<cv::Mat> ours = decode_grey16_png(png);
  ASSERT_TRUE(ours);
  EXPECT_TRUE(same(*ours, image));
  // libpng's own encoder (adaptive filters) too.
  Bytes written;
  ASSERT_TRUE(cv::imencode(".png", image, written));
  ASSERT_TRUE(decode_grey16_png(written));
  EXPECT_TRUE(same(*decode_grey16_png(written), image));
}

TEST(ImageDecoding, PngsTheFastPathDoesNotHandleGoToOpenCv) {
  const cv::Mat image = depth_like(12, 10, 5);
  PngLayout interlaced, transparent, unknown_critical, not_a_name, small_window;
  interlaced.interlace = 1;
  transparent.extra_chunks = {{"tRNS", Bytes{0, 0}}};
  unknown_critical.extra_chunks = {{"ABCD", Bytes{1}}};
  not_a_name.extra_chunks = {{"a1bc", Bytes{1}}};  // libpng refuses a chunk name that is not four letters
  small_window.window_bits = 9;  // 512 bytes, less than the image's data: zlib enforces it, libdeflate would not
  for (const PngLayout& layout : {interlaced, transparent, unknown_critical, not_a_name, small_window}) {
    const Bytes png = make_png(layout.window_bits < 15 ? depth_like(40, 33, 6) : image, layout);
    EXPECT_FALSE(decode_grey16_png(png)) << "layout with window " << layout.window_bits << " interlace "
                                         << layout.interlace << " chunks " << layout.extra_chunks.size();
    EXPECT_TRUE(same(decode_unchanged_image(png), opencv(png, cv::IMREAD_UNCHANGED)));
  }

  const cv::Mat colour(12, 10, CV_8UC3, cv::Scalar(1, 2, 3)), grey8(12, 10, CV_8UC1, cv::Scalar(9));
  for (const cv::Mat& other : {colour, grey8, cv::Mat(cv::Mat(12, 10, CV_16UC3, cv::Scalar(1000, 2, 3)))}) {
    Bytes png;
    ASSERT_TRUE(cv::imencode(".png", other, png));
    EXPECT_FALSE(decode_grey16_png(png));
    EXPECT_TRUE(same(decode_unchanged_image(png), opencv(png, cv::IMREAD_UNCHANGED)));
    EXPECT_TRUE(same(decode_unchanged_image(png), other));
  }
}

TEST(ImageDecoding, DamagedPngsAreRefusedByTheFastPathAndDecodeAsOpenCvDecodesThem) {
  const Bytes good = make_png(depth_like(20, 16, 9), PngLayout{});
  Bytes bad_crc = good, bad_data = good, bad_filter = good;
  bad_crc[45] ^= 0x10;                 // inside IDAT's data: the chunk's CRC no longer matches
  PngLayout unknown_filter;
  unknown_filter.filters = {5};  // filter type 5 does not exist
  bad_filter = make_png(depth_like(20, 16, 9), unknown_filter);
  bad_data.resize(good.size() - 30);   // cut inside IDAT: no IEND
  const Bytes truncated_header(good.begin(), good.begin() + 20);
  for (const Bytes& b : {bad_crc, bad_data, bad_filter, truncated_header, Bytes{}, Bytes{0x89, 'P'}}) {
    EXPECT_FALSE(decode_grey16_png(b));
    EXPECT_TRUE(same(decode_unchanged_image(b), b.empty() ? cv::Mat() : opencv(b, cv::IMREAD_UNCHANGED)));
  }
}

// The file with its header's width and height replaced (and the header's CRC made right again).
Bytes with_header_size(Bytes png, std::uint32_t width, std::uint32_t height) {
  Bytes size;
  put_be32(size, width);
  put_be32(size, height);
  std::copy(size.begin(), size.end(), png.begin() + 16);  // IHDR data starts after signature, length and type
  const auto crc = static_cast<std::uint32_t>(crc32(0, png.data() + 12, 17));
  Bytes crc_bytes;
  put_be32(crc_bytes, crc);
  std::copy(crc_bytes.begin(), crc_bytes.end(), png.begin() + 29);
  return png;
}

TEST(ImageDecoding, AHeaderPromisingMorePixelsThanTheFileHoldsIsNoImage) {
  const Bytes small = make_png(depth_like(8, 8, 1), PngLayout{});
  // Within the fast path's side limit, but more than the few compressed bytes can expand to.
  EXPECT_FALSE(decode_grey16_png(with_header_size(small, 16384, 16384)));
  // Over OpenCV's pixel limit, where OpenCV throws: the decoder says "no image".
  const Bytes huge = with_header_size(small, 40000, 40000);
  EXPECT_THROW(cv::imdecode(huge, cv::IMREAD_UNCHANGED), cv::Exception);
  EXPECT_TRUE(decode_unchanged_image(huge).empty());
}

// ---- JPEG ----

cv::Mat colour_like(int rows, int cols) {
  cv::Mat m(rows, cols, CV_8UC3);
  cv::RNG rng(11);
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x)
      m.at<cv::Vec3b>(y, x) = cv::Vec3b(std::uint8_t(x * 5), std::uint8_t(y * 7 + rng.uniform(0, 40)),
                                        std::uint8_t((x + y) * 3));
  return m;
}

TEST(ImageDecoding, ColourJpegGivesOpenCvsBgrPixels) {
  // Baseline at two qualities, progressive, with restart markers, with optimised Huffman tables.
  const std::vector<std::vector<int>> encodings = {{cv::IMWRITE_JPEG_QUALITY, 50},
                                                   {cv::IMWRITE_JPEG_QUALITY, 95},
                                                   {cv::IMWRITE_JPEG_PROGRESSIVE, 1},
                                                   {cv::IMWRITE_JPEG_RST_INTERVAL, 2},
                                                   {cv::IMWRITE_JPEG_OPTIMIZE, 1}};
  for (const cv::Size size : {cv::Size(37, 29), cv::Size(64, 48)})
    for (std::size_t k = 0; k < encodings.size(); ++k) {
      Bytes jpeg;
      const cv::Mat image = colour_like(size.height, size.width);
      ASSERT_TRUE(cv::imencode(".jpg", image, jpeg, encodings[k]));
      const std::optional<cv::Mat> ours = decode_ycbcr_jpeg_to_bgr(jpeg);
      ASSERT_TRUE(ours) << size << " encoding " << k;
      EXPECT_TRUE(same(*ours, opencv(jpeg, cv::IMREAD_COLOR))) << size << " encoding " << k;
    }
}

// An APP1 segment with an EXIF orientation tag (6: turned 90 degrees), inserted after SOI, under `label` (the fast
// path leaves every APP1 segment to OpenCV, whatever its label).
Bytes with_exif_orientation(const Bytes& jpeg, const std::string& label = std::string("Exif\0\0", 6)) {
  const Bytes tiff = {'I', 'I', 42, 0, 8, 0, 0, 0,  // little-endian TIFF header, first IFD at 8
                      1, 0,                          // one entry
                      0x12, 0x01, 3, 0, 1, 0, 0, 0, 6, 0, 0, 0,  // orientation (SHORT, 1 value) = 6
                      0, 0, 0, 0};                   // no next IFD
  const std::size_t length = 2 + label.size() + tiff.size();  // the segment's length field counts itself
  const Bytes marker = {0xFF, 0xE1, static_cast<std::uint8_t>(length >> 8), static_cast<std::uint8_t>(length & 0xFF)};
  const Bytes soi(jpeg.begin(), jpeg.begin() + 2), rest(jpeg.begin() + 2, jpeg.end()), name(label.begin(), label.end());
  Bytes out;
  for (const Bytes* part : {&soi, &marker, &name, &tiff, &rest})
    for (std::uint8_t byte : *part) out.push_back(byte);
  return out;
}

TEST(ImageDecoding, JpegsTheFastPathDoesNotHandleGoToOpenCv) {
  Bytes plain, grey;
  ASSERT_TRUE(cv::imencode(".jpg", colour_like(24, 40), plain));
  ASSERT_TRUE(cv::imencode(".jpg", cv::Mat(24, 40, CV_8UC1, cv::Scalar(77)), grey));
  const Bytes turned = with_exif_orientation(plain), turned_odd_label = with_exif_orientation(plain, "XMPx\0\0");
  Bytes cut(plain.begin(), plain.begin() + std::ptrdiff_t(plain.size() / 2));
  for (const Bytes& b : {turned, turned_odd_label, grey, cut, Bytes{0xFF, 0xD8, 0xFF}}) {
    EXPECT_FALSE(decode_ycbcr_jpeg_to_bgr(b));
    EXPECT_TRUE(same(decode_colour_image(b), opencv(b, cv::IMREAD_COLOR)));
  }
  EXPECT_EQ(decode_colour_image(turned).size(), cv::Size(24, 40));  // OpenCV turned it, as it does any file
}

TEST(ImageDecoding, BytesOpenCvWouldTakeForAnotherFormatAreNoImage) {
  // OpenCV's DICOM reader recognises "DICM" at byte 128 and aborts the process on a damaged file.
  Bytes dicom(128, 0);
  for (char c : std::string("DICM")) dicom.push_back(static_cast<std::uint8_t>(c));
  dicom.resize(400, 0);
  EXPECT_TRUE(decode_colour_image(dicom).empty());
  EXPECT_TRUE(decode_unchanged_image(dicom).empty());
  Bytes bmp;
  ASSERT_TRUE(cv::imencode(".bmp", colour_like(8, 8), bmp));
  EXPECT_TRUE(decode_colour_image(bmp).empty());  // a real image, but not one of the two formats
}

TEST(ImageDecoding, TheRealKitchensFilesTakeTheFastPaths) {
  // The two kinds of file the fast paths exist for, as a Kinect v1 dataset stores them: if a check refused them,
  // every frame would silently go the slow way.
  const std::filesystem::path kitchen = std::filesystem::path(VARSLAM_SHARED_DIR) / "realdata/7scenes_redkitchen";
  if (!std::filesystem::exists(kitchen)) GTEST_SKIP() << "no " << kitchen;
  const std::optional<Bytes> jpeg = read_file_bytes(kitchen / "rgb/frame-000000.color.jpg");
  const std::optional<Bytes> png = read_file_bytes(kitchen / "depth/frame-000000.depth.png");
  ASSERT_TRUE(jpeg && png);
  const std::optional<cv::Mat> bgr = decode_ycbcr_jpeg_to_bgr(*jpeg), depth = decode_grey16_png(*png);
  ASSERT_TRUE(bgr && depth);
  EXPECT_TRUE(same(*bgr, opencv(*jpeg, cv::IMREAD_COLOR)));
  EXPECT_TRUE(same(*depth, opencv(*png, cv::IMREAD_UNCHANGED)));
}

TEST(ImageDecoding, FileBytesAreReadWholeAndAMissingFileIsNoBytes) {
  const auto file =
      std::filesystem::temp_directory_path() / ("varslam_image_decoding_bytes_" + std::to_string(::getpid()) + ".bin");
  const Bytes content = {0, 1, 2, 255, 10, 13};
  {
    std::ofstream out(file, std::ios::binary);
    out.write(reinterpret_cast<const char*>(content.data()), std::streamsize(content.size()));
  }
  EXPECT_EQ(read_file_bytes(file), content);
  std::filesystem::remove(file);
  EXPECT_FALSE(read_file_bytes(file));
}

}  // namespace
}  // namespace varslam
