#include "report/html.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "report/html_check.hpp"

namespace varslam::report {
namespace {

std::vector<std::uint8_t> bytes(const std::string& s) { return {s.begin(), s.end()}; }

TEST(Base64, MatchesTheRfc4648TestVectors) {
  EXPECT_EQ(base64_encode(bytes("")), "");
  EXPECT_EQ(base64_encode(bytes("f")), "Zg==");
  EXPECT_EQ(base64_encode(bytes("fo")), "Zm8=");
  EXPECT_EQ(base64_encode(bytes("foo")), "Zm9v");
  EXPECT_EQ(base64_encode(bytes("foob")), "Zm9vYg==");
  EXPECT_EQ(base64_encode(bytes("fooba")), "Zm9vYmE=");
  EXPECT_EQ(base64_encode(bytes("foobar")), "Zm9vYmFy");
  EXPECT_EQ(base64_encode({0xff, 0xfe, 0x00}), "//4A");
}

TEST(HtmlEscape, EscapesMarkupCharacters) {
  EXPECT_EQ(html_escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&#39;");
  EXPECT_EQ(html_escape("plain"), "plain");
}

TEST(InlineSvg, DropsTheXmlPrologAndBalances) {
  Plot p({"t", "x", "y", 300, 200, false, true});
  p.add_line("l", {0, 1, 2}, {1, 3, 2});
  const std::string svg = inline_svg(p);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_EQ(svg.find("<?xml"), std::string::npos);
  EXPECT_EQ(testing::html_tag_balance_problem(svg), "");
}

TEST(ImageDataUri, ShrinksWideImagesToJpeg) {
  const auto file = std::filesystem::temp_directory_path() / "varslam_report_html_test.png";
  cv::imwrite(file.string(), cv::Mat(100, 3000, CV_8UC3, cv::Scalar(10, 200, 30)));
  const auto uri = image_data_uri(file, 600);
  ASSERT_TRUE(uri.has_value());
  EXPECT_EQ(uri->rfind("data:image/jpeg;base64,", 0), 0u);
  EXPECT_LT(uri->size(), 20000u);  // a flat 600x20 JPEG
  EXPECT_FALSE(image_data_uri(file.string() + ".missing").has_value());
  std::filesystem::remove(file);
}

TEST(HtmlCheck, CatchesUnbalancedTags) {
  EXPECT_EQ(testing::html_tag_balance_problem("<p><b>x</b></p><img src=\"a\"><br>"), "");
  EXPECT_NE(testing::html_tag_balance_problem("<p><b>x</p></b>"), "");
  EXPECT_NE(testing::html_tag_balance_problem("<table><tr><td>1</td></tr>"), "");
}

TEST(FormatNumber, FixedDecimalsAndNotAvailable) {
  EXPECT_EQ(format_number(1.23456, 2), "1.23");
  EXPECT_EQ(format_number(std::nan(""), 2), "n/a");
}

}  // namespace
}  // namespace varslam::report
