#include "viewer/viewer_server.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <httplib.h>

#include <atomic>
#include <thread>

#include "core/error.hpp"

namespace varslam::viewer {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

std::vector<Asset> fake_assets() {
  return {{"/", "text/html", "<html>page</html>"}, {"/viewer.js", "text/javascript", "console.log(1)"}};
}

/// Reads /events until `stop(text)` says enough (or `limit` passes); returns what arrived.
std::string read_events(int port, const std::function<bool(const std::string&)>& stop,
                        std::chrono::milliseconds limit = 5000ms) {
  httplib::Client c("127.0.0.1", port);
  c.set_read_timeout(std::chrono::duration_cast<std::chrono::seconds>(limit).count() + 1, 0);
  std::string got;
  const auto t0 = std::chrono::steady_clock::now();
  c.Get("/events", [&](const char* data, std::size_t n) {
    got.append(data, n);
    return !stop(got) && std::chrono::steady_clock::now() - t0 < limit;
  });
  return got;
}

TEST(ViewerServer, ServesItsOwnAssetsAndNothingElse) {
  ViewerBoard board;
  ViewerServer server(board, fake_assets(), {});
  ASSERT_GT(server.port(), 0);
  EXPECT_THAT(server.url(), HasSubstr("http://127.0.0.1:"));
  httplib::Client c("127.0.0.1", server.port());
  auto r = c.Get("/");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->body, "<html>page</html>");
  EXPECT_EQ(c.Get("/viewer.js")->body, "console.log(1)");
  for (const char* path : {"/etc/passwd", "/../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/viewer.js/../../x",
                           "/frame?i=0", "/index.html"})
    EXPECT_EQ(c.Get(path)->status, 404) << path;
}

TEST(ViewerServer, StreamsTheBoardAsServerSentEvents) {
  ViewerBoard board;
  board.set_greeting(sse_event("hello", "{}"));
  board.append(sse_event("loop", R"({"query":4})"));
  board.set_frame(sse_event("frame", R"({"index":3})"));
  ViewerServer server(board, fake_assets(), {});
  const std::string got = read_events(server.port(), [](const std::string& s) { return s.find("frame") != s.npos; });
  EXPECT_EQ(got.find("event: hello"), 0u);
  EXPECT_THAT(got, HasSubstr("event: loop\ndata: {\"query\":4}\n\n"));
  EXPECT_THAT(got, HasSubstr("event: frame\ndata: {\"index\":3}"));
}

TEST(ViewerServer, ABrowserThatLeavesIsNoticedAndOneThatComesBackGetsTheLogAgain) {
  ViewerBoard board;
  board.set_greeting(sse_event("hello", "{}"));
  board.append(sse_event("loop", "{}"));
  ViewerServer server(board, fake_assets(), {});
  EXPECT_THAT(read_events(server.port(), [](const std::string& s) { return s.find("loop") != s.npos; }),
              HasSubstr("event: loop"));
  // The server notices the closed connection at its next write (a keep-alive comment at the latest).
  const auto t0 = std::chrono::steady_clock::now();
  while (board.clients() > 0 && std::chrono::steady_clock::now() - t0 < 5s) std::this_thread::sleep_for(20ms);
  EXPECT_EQ(board.clients(), 0);
  board.append(sse_event("relocalization", "{}"));
  const std::string again =
      read_events(server.port(), [](const std::string& s) { return s.find("relocalization") != s.npos; });
  EXPECT_EQ(again.find("event: hello"), 0u);
  EXPECT_THAT(again, HasSubstr("event: loop"));
  EXPECT_THAT(again, HasSubstr("event: relocalization"));
}

TEST(ViewerServer, ATakenPortIsRefusedByName) {
  ViewerBoard board;
  ViewerServer first(board, fake_assets(), {});
  ViewerBoard other;
  try {
    ViewerServer second(other, fake_assets(), {"127.0.0.1", first.port()});
    ADD_FAILURE() << "bound a taken port";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("127.0.0.1:" + std::to_string(first.port())));
    EXPECT_THAT(e.what(), HasSubstr("taken"));
  }
}

TEST(ViewerServer, StopEndsOpenStreams) {
  ViewerBoard board;
  board.set_greeting(sse_event("hello", "{}"));
  auto server = std::make_unique<ViewerServer>(board, fake_assets(), ServerOptions{});
  const int port = server->port();
  std::atomic<bool> ended{false};
  std::thread client([&] {
    read_events(
        port, [](const std::string&) { return false; }, 20000ms);
    ended = true;
  });
  const auto t0 = std::chrono::steady_clock::now();
  while (board.clients() == 0 && std::chrono::steady_clock::now() - t0 < 5s) std::this_thread::sleep_for(10ms);
  ASSERT_EQ(board.clients(), 1);
  server->stop();
  client.join();
  EXPECT_TRUE(ended);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 10s);
}

TEST(ViewerServer, MoreStreamsThanAllowedAreAnswered503) {
  ViewerBoard board;
  board.set_greeting(sse_event("hello", "{}"));
  ViewerServer server(board, fake_assets(), {"127.0.0.1", 0, 1});
  std::thread first([&] {
    read_events(
        server.port(), [](const std::string&) { return false; }, 1500ms);
  });
  const auto t0 = std::chrono::steady_clock::now();
  while (board.clients() == 0 && std::chrono::steady_clock::now() - t0 < 5s) std::this_thread::sleep_for(10ms);
  httplib::Client c("127.0.0.1", server.port());
  auto r = c.Get("/events");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 503);
  first.join();
}

TEST(ViewerServer, FinishedRunFramesComeByNumberOnly) {
  ViewerBoard board;
  ViewerServer server(board, fake_assets(), {}, [](std::size_t i) -> std::optional<std::string> {
    if (i < 3) return "jpeg" + std::to_string(i);
    return std::nullopt;
  });
  httplib::Client c("127.0.0.1", server.port());
  EXPECT_EQ(c.Get("/frame?i=2")->body, "jpeg2");
  for (const char* bad : {"/frame?i=3", "/frame?i=-1", "/frame?i=1x", "/frame?i=../x", "/frame"})
    EXPECT_EQ(c.Get(bad)->status, 404) << bad;
}

TEST(ViewerAssets, TheBuiltPageIsFoundNextToTheBinaryAndAMissingFolderIsNamed) {
  const std::vector<Asset> assets = load_assets();
  ASSERT_GE(assets.size(), 6u);
  EXPECT_EQ(assets[0].url, "/");
  EXPECT_THAT(assets[0].body, HasSubstr("viewer.js"));
  // A folder given first is searched first; the build tree's copy is still found after it.
  const auto search = asset_search_path(std::filesystem::path("/nonexistent/viewer"));
  EXPECT_EQ(search.front(), "/nonexistent/viewer");
  EXPECT_NO_THROW((void)load_assets(std::filesystem::path("/nonexistent/viewer")));
  try {
    (void)load_assets_from({"/nonexistent/a", "/nonexistent/b"});
    ADD_FAILURE() << "found assets in folders that do not exist";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/a, /nonexistent/b"));
    EXPECT_THAT(e.what(), HasSubstr("VARSLAM_VIEWER_DIR"));
  }
}

}  // namespace
}  // namespace varslam::viewer
