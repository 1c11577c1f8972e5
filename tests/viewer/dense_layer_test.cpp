#include "viewer/dense_layer.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "dense/dense_mapper.hpp"

namespace varslam::viewer {
namespace {

using namespace std::chrono_literals;

// A deterministic dense map of one keyframe seeing a wall 2 m ahead.
std::shared_ptr<dense::DenseMapper> wall_map() {
  PinholeCamera c;
  c.width = 160;
  c.height = 120;
  c.fx = c.fy = 130;
  c.cx = 79.5;
  c.cy = 59.5;
  dense::DenseConfig cfg;
  cfg.pixel_step = 1;
  auto map = std::make_shared<dense::DenseMapper>(cfg, c, false);
  dense::DenseKeyframe kf;
  kf.depth = cv::Mat(c.height, c.width, CV_32FC1, cv::Scalar(2.0f));
  kf.pose = [] { return Eigen::Isometry3d::Identity(); };
  map->add(kf);
  return map;
}

// The dense messages a fresh client gets from the board: region key -> point count.
std::map<std::string, int> regions_on(ViewerBoard& board) {
  ViewerBoard::Cursor c;
  std::map<std::string, int> out;
  for (const Message& m : board.wait_news(c, 1ms)) {
    if (m->rfind("event: dense\n", 0) != 0) continue;
    const nlohmann::json j = nlohmann::json::parse(m->substr(m->find("data: ") + 6));
    out[j["key"]] = j["count"];
  }
  return out;
}

TEST(DenseLayer, PostsTheRegionsOfTheSurfaceAndTakesThemOffWhenTheMapIsReplaced) {
  ViewerBoard board;
  board.set_greeting("event: hello\ndata: {}\n\n");
  const auto map = wall_map();
  DenseLayer layer(map, board, {});
  while (map->preview_step()) {  // deterministic: what the layer's thread does before reading
  }
  layer.update();
  std::map<std::string, int> regions = regions_on(board);
  int points = 0;
  for (const auto& [key, n] : regions) points += n;
  const DenseLayerStats s = layer.stats();
  EXPECT_GT(regions.size(), 4u);
  EXPECT_EQ(static_cast<std::size_t>(points), s.points);
  EXPECT_EQ(regions.size(), s.regions);
  EXPECT_EQ(s.updates, 1u);
  layer.update();  // nothing changed: nothing sent
  EXPECT_EQ(layer.stats().regions_sent, s.regions_sent);
  layer.clear();
  for (const auto& [key, n] : regions_on(board)) EXPECT_EQ(n, 0) << key;
}

}  // namespace
}  // namespace varslam::viewer
