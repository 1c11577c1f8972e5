#include "io/boxes_io.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "io/temp_dir.hpp"

namespace varslam {
namespace {

using ::testing::HasSubstr;
using varslam::testing::TempDir;

Detection box(double t, const std::string& label, float score, float x, float y, float w, float h) {
  Detection d;
  d.timestamp = t;
  d.label = label;
  d.score = score;
  d.box = cv::Rect2f(x, y, w, h);
  return d;
}

TEST(BoxesIo, RoundTripGroupsBoxesByTimestamp) {
  TempDir dir;
  BoxesByTime boxes;
  boxes[1.0] = {box(1.0, "person", 0.9f, 10.5f, 20.f, 30.f, 80.5f), box(1.0, "chair", 0.5f, 0, 0, 5, 5)};
  boxes[1.033333] = {box(1.033333, "person", 1.0f, 11.f, 21.f, 30.f, 80.f)};
  write_boxes_file(boxes, dir / "boxes.txt");
  const BoxesByTime back = read_boxes_file(dir / "boxes.txt");
  ASSERT_EQ(back.size(), 2u);
  for (const auto& [t, dets] : boxes) {
    auto it = back.lower_bound(t - 1e-6);
    ASSERT_NE(it, back.end());
    EXPECT_NEAR(it->first, t, 1e-6);
    ASSERT_EQ(it->second.size(), dets.size());
    for (std::size_t i = 0; i < dets.size(); ++i) {
      EXPECT_EQ(it->second[i].label, dets[i].label);
      EXPECT_NEAR(it->second[i].score, dets[i].score, 1e-3);
      EXPECT_NEAR(it->second[i].box.x, dets[i].box.x, 0.05);
      EXPECT_NEAR(it->second[i].box.y, dets[i].box.y, 0.05);
      EXPECT_NEAR(it->second[i].box.width, dets[i].box.width, 0.05);
      EXPECT_NEAR(it->second[i].box.height, dets[i].box.height, 0.05);
    }
  }
}

TEST(BoxesIo, MalformedLineNamesFileAndLine) {
  TempDir dir;
  const auto file = dir.write("b.txt", "# comment\n1.0 person 0.9 1 2 3 4\n1.1 person 0.9 1 2 three 4\n");
  try {
    read_boxes_file(file);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(file.string() + ":3:"));
  }
  const auto neg = dir.write("n.txt", "1.0 person 0.9 1 2 -3 4\n");
  EXPECT_THROW(read_boxes_file(neg), InputError);
  EXPECT_THROW(read_boxes_file(dir / "missing.txt"), InputError);
}

TEST(BoxesIo, BoxesNearPicksTheClosestFrameWithinTolerance) {
  BoxesByTime boxes;
  boxes[1.0] = {box(1.0, "a", 1, 0, 0, 1, 1)};
  boxes[1.03] = {box(1.03, "b", 1, 0, 0, 1, 1)};
  EXPECT_EQ(boxes_near(boxes, 1.012).at(0).label, "a");
  EXPECT_EQ(boxes_near(boxes, 1.018).at(0).label, "b");
  EXPECT_EQ(boxes_near(boxes, 0.99).at(0).label, "a");
  EXPECT_TRUE(boxes_near(boxes, 1.2).empty());
  EXPECT_TRUE(boxes_near(boxes, 0.5).empty());
  EXPECT_TRUE(boxes_near({}, 1.0).empty());
}

}  // namespace
}  // namespace varslam
