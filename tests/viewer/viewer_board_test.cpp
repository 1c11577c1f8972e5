#include "viewer/viewer_board.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace varslam::viewer {
namespace {

using namespace std::chrono_literals;

std::vector<std::string> texts(const std::vector<Message>& ms) {
  std::vector<std::string> out;
  for (const Message& m : ms) out.push_back(*m);
  return out;
}

TEST(ViewerBoard, NothingIsSentBeforeTheGreetingThenTheGreetingComesFirst) {
  ViewerBoard b;
  ViewerBoard::Cursor c;
  b.set_frame("f1");
  EXPECT_TRUE(b.wait_news(c, 1ms).empty());
  b.set_greeting("hello");
  b.append("a1");
  EXPECT_EQ(texts(b.wait_news(c, 1ms)), (std::vector<std::string>{"hello", "a1", "f1"}));
  EXPECT_TRUE(b.wait_news(c, 1ms).empty());  // nothing new
}

TEST(ViewerBoard, ASlowClientSkipsToTheNewestFrameAndMapButGetsTheWholeLog) {
  ViewerBoard b;
  b.set_greeting("hello");
  ViewerBoard::Cursor c;
  (void)b.wait_news(c, 1ms);
  for (int i = 0; i < 10; ++i) {
    b.set_frame("frame" + std::to_string(i));
    b.set_map("map" + std::to_string(i));
    b.append("event" + std::to_string(i));
  }
  const auto news = texts(b.wait_news(c, 1ms));
  ASSERT_EQ(news.size(), 12u);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(news[i], "event" + std::to_string(i));
  EXPECT_EQ(news[10], "map9");
  EXPECT_EQ(news[11], "frame9");
  EXPECT_EQ(b.frames_set(), 10u);
  EXPECT_EQ(b.frames_sent(), 1u);
}

TEST(ViewerBoard, ALateOrReconnectingClientStartsFromTheCurrentStateAndTheWholeLog) {
  ViewerBoard b;
  b.set_greeting("hello");
  b.append("loop");
  b.set_map("map2");
  b.set_frame("frame7");
  ViewerBoard::Cursor fresh;
  EXPECT_EQ(texts(b.wait_news(fresh, 1ms)), (std::vector<std::string>{"hello", "loop", "map2", "frame7"}));
}

TEST(ViewerBoard, DenseRegionsGoOutWhenTheyChangeInTheirNewestVersionAndWholeToALateClient) {
  ViewerBoard b;
  b.set_greeting("hello");
  ViewerBoard::Cursor c;
  (void)b.wait_news(c, 1ms);
  b.set_dense_region("0,0,0", "a1");
  b.set_dense_region("0,0,1", "b1");
  EXPECT_EQ(texts(b.wait_news(c, 1ms)), (std::vector<std::string>{"a1", "b1"}));
  b.set_dense_region("0,0,1", "b2");
  b.set_dense_region("0,0,1", "b3");  // a slow client skips b2
  EXPECT_EQ(texts(b.wait_news(c, 1ms)), (std::vector<std::string>{"b3"}));
  EXPECT_TRUE(b.wait_news(c, 1ms).empty());
  ViewerBoard::Cursor late;
  EXPECT_EQ(texts(b.wait_news(late, 1ms)), (std::vector<std::string>{"hello", "a1", "b3"}));
}

TEST(ViewerBoard, AWaitingClientWakesOnNewsAndOnClose) {
  ViewerBoard b;
  b.set_greeting("hello");
  ViewerBoard::Cursor c;
  (void)b.wait_news(c, 1ms);
  std::thread writer([&] {
    std::this_thread::sleep_for(20ms);
    b.set_frame("f");
  });
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(texts(b.wait_news(c, 5s)), (std::vector<std::string>{"f"}));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 4s);
  writer.join();
  std::thread closer([&] {
    std::this_thread::sleep_for(20ms);
    b.close();
  });
  EXPECT_TRUE(b.wait_news(c, 5s).empty());
  closer.join();
  EXPECT_TRUE(b.closed());
}

TEST(ViewerBoard, ServerSentEventFormat) {
  EXPECT_EQ(sse_event("map", R"({"a":1})"), "event: map\ndata: {\"a\":1}\n\n");
}

}  // namespace
}  // namespace varslam::viewer
