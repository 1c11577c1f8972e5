#include "viewer/live_viewer.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/error.hpp"
#include "slam/e2e_support.hpp"
#include "file_text.hpp"
// Last: glibc's resolv.h, which it includes, defines a macro `_res` that breaks Eigen's headers after it.
#include <fmt/format.h>
#include <httplib.h>

namespace varslam::viewer {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using ::testing::HasSubstr;

fs::path walking_sequence() { return slam::e2e::pipeline_walking_sequence(); }

using test::slurp;

run::RunSummary run_walking(const std::string& name, std::vector<Observer*> observers, bool dense = false) {
  run::RunOptions ro;
  ro.progress = false;
  ro.observers = std::move(observers);
  const fs::path out = fs::temp_directory_path() / ("varslam_viewer_" + name + "_" + std::to_string(::getpid()));
  std::vector<std::string> settings{"semantic.detector=boxes"};
  if (dense) settings.push_back("dense.enabled=true");
  return slam::e2e::run_with(walking_sequence(), out, ro, settings);
}

// The data lines of every server-sent event `name` in a stream, parsed.
std::vector<nlohmann::json> events_named(const std::string& stream, const std::string& name) {
  std::vector<nlohmann::json> out;
  const std::string head = "event: " + name + "\ndata: ";
  for (std::size_t at = stream.find(head); at != std::string::npos; at = stream.find(head, at + 1)) {
    const std::size_t begin = at + head.size(), end = stream.find('\n', begin);
    if (end == std::string::npos) break;  // cut off by the end of the read
    out.push_back(nlohmann::json::parse(stream.substr(begin, end - begin)));
  }
  return out;
}

std::size_t base64_bytes(const std::string& b64) {
  std::size_t pad = 0;
  for (auto it = b64.rbegin(); it != b64.rend() && *it == '='; ++it) ++pad;
  return b64.size() / 4 * 3 - pad;
}

/// A browser stand-in: reads /events on its own thread until told to stop.
class EventReader {
 public:
  explicit EventReader(int port)
      : thread_([this, port] {
          httplib::Client c("127.0.0.1", port);
          c.set_read_timeout(60, 0);
          c.Get("/events", [this](const char* data, std::size_t n) {
            std::lock_guard lock(mutex_);
            text_.append(data, n);
            return !stop_.load();
          });
        }) {}
  ~EventReader() { finish(); }
  void finish() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  std::string text() const {
    std::lock_guard lock(mutex_);
    return text_;
  }
  bool wait_for(const std::string& what, std::chrono::milliseconds limit) const {
    const auto t0 = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() - t0 < limit) {
      if (text().find(what) != std::string::npos) return true;
      std::this_thread::sleep_for(20ms);
    }
    return false;
  }

 private:
  mutable std::mutex mutex_;
  std::string text_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

TEST(LiveViewer, TheTrajectoryIsByteIdenticalWithAndWithoutTheViewerAndABrowserConnected) {
  const run::RunSummary plain = run_walking("plain", {});
  LiveViewer viewer({});
  EventReader browser(viewer.port());
  ASSERT_TRUE(browser.wait_for("event: hello", 5s));
  const run::RunSummary watched = run_walking("watched", {&viewer});
  EXPECT_EQ(slurp(plain.out_dir / "CameraTrajectory.txt"), slurp(watched.out_dir / "CameraTrajectory.txt"));
  EXPECT_EQ(slurp(plain.out_dir / "LiveTrajectory.txt"), slurp(watched.out_dir / "LiveTrajectory.txt"));
  ASSERT_TRUE(browser.wait_for("event: done", 10s));
  const std::string got = browser.text();
  EXPECT_THAT(got, HasSubstr("event: frame"));
  EXPECT_THAT(got, HasSubstr("event: map"));
  EXPECT_THAT(got, HasSubstr("event: alpha"));
  EXPECT_THAT(got, HasSubstr("\"final\":true"));
  const LiveViewerStats s = viewer.stats();
  EXPECT_EQ(s.frames_seen, watched.frames);
  EXPECT_GT(s.frames_encoded, 0u);
  EXPECT_LE(s.frames_encoded, s.frames_seen);
  EXPECT_GE(s.maps_encoded, 1u);
  browser.finish();
}

// The dense map's layer: regions of surface points while the run goes on (deterministic mode: the layer fuses the
// keyframes for the view itself) and the final map at the end; the files written are those of a run without it.
TEST(LiveViewer, TheDenseLayerSendsWellFormedRegionsAndLeavesTheRunsFilesAsTheyWere) {
  const run::RunSummary plain = run_walking("dense_plain", {}, true);
  LiveViewerOptions o;
  o.dense.rate = 20;  // the test's run takes a few seconds: update often
  LiveViewer viewer(o);
  EventReader browser(viewer.port());
  ASSERT_TRUE(browser.wait_for("event: hello", 5s));
  const run::RunSummary watched = run_walking("dense_watched", {&viewer}, true);
  for (const char* f : {"CameraTrajectory.txt", "dense_mesh.ply", "dense_map.bt"})
    EXPECT_EQ(slurp(plain.out_dir / f), slurp(watched.out_dir / f)) << f;
  ASSERT_TRUE(browser.wait_for("event: done", 10s));
  std::this_thread::sleep_for(300ms);  // the last regions through the stream
  browser.finish();
  const std::vector<nlohmann::json> regions = events_named(browser.text(), "dense");
  ASSERT_FALSE(regions.empty());
  std::map<std::string, std::size_t> newest;  // region -> points, as the page keeps them
  for (const nlohmann::json& r : regions) {
    ASSERT_TRUE(r.contains("key") && r.contains("origin") && r.contains("unit") && r.contains("cell"));
    const std::size_t n = r["count"];
    EXPECT_EQ(base64_bytes(r["xyz"]), n * 3 * sizeof(std::int16_t));
    EXPECT_EQ(base64_bytes(r["rgb"]), n * 3);
    EXPECT_GT(r["unit"].get<double>(), 0);
    EXPECT_DOUBLE_EQ(r["cell"].get<double>(), 0.04);  // 2-cm voxels, two per cell
    newest[r["key"]] = n;
  }
  std::size_t points = 0;
  for (const auto& [key, n] : newest) points += n;
  const LiveViewerStats s = viewer.stats();
  ASSERT_TRUE(s.dense.has_value());
  EXPECT_GE(s.dense->updates, 2u);  // during the run and the final one
  EXPECT_EQ(s.dense->points, points);
  EXPECT_GT(points, 2000u);
  EXPECT_LE(s.dense->max_update_bytes, 16u * 1024 * 1024);
}

TEST(LiveViewer, WithoutABrowserNothingIsEncodedButTheFinalStateWaitsForOne) {
  LiveViewer viewer({});
  const run::RunSummary r = run_walking("absent", {&viewer});
  const LiveViewerStats before = viewer.stats();
  EXPECT_EQ(before.frames_seen, r.frames);
  EXPECT_EQ(before.frames_encoded, 0u);  // no browser: no JPEG, no JSON
  EXPECT_EQ(before.maps_encoded, 0u);    // the final map is encoded by on_finished, not the encoder
  EventReader late(viewer.port());       // a browser that comes after the run
  // Waits for a field inside the frame event, not its header: the event may arrive in more than one read.
  ASSERT_TRUE(late.wait_for(fmt::format("\"index\":{}", r.frames - 1), 5s));
  const std::string got = late.text();
  EXPECT_EQ(got.find("event: hello"), 0u);
  EXPECT_THAT(got, HasSubstr("\"final\":true"));
  EXPECT_THAT(got, HasSubstr("event: done"));
  EXPECT_THAT(got, HasSubstr(fmt::format("\"index\":{}", r.frames - 1)));  // the newest frame
}

TEST(LiveViewer, APortInUseFailsBeforeTheRun) {
  LiveViewer first({});
  LiveViewerOptions o;
  o.server.port = first.port();
  EXPECT_THROW(LiveViewer second(o), InputError);
}

}  // namespace
}  // namespace varslam::viewer
