#pragma once
// What the viewer's browsers are sent, kept as ready-to-send server-sent-event texts: a greeting, the newest frame,
// the newest map, the newest version of each region of the dense map's layer, and an append-only log (alpha per keyframe, loops, relocalizations) that every client gets whole.
// A client that falls behind skips to the newest frame and map, so a slow browser drops updates instead of queueing
// them, and a browser that connects late (or reconnects) starts from the current state and the whole log.
// Written by the viewer's encoder thread, read by one server thread per client.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace varslam::viewer {

using Message = std::shared_ptr<const std::string>;

class ViewerBoard {
 public:
  /// What one client has been sent so far.
  struct Cursor {
    bool greeted = false;
    std::uint64_t frame = 0, map = 0, dense = 0;
    std::size_t log = 0;
  };

  void set_greeting(std::string message);
  void set_frame(std::string message);
  void set_map(std::string message);
  void append(std::string message);
  /// One region of the dense layer (replacing the region's previous message): a client is sent each region that
  /// changed since it was last served, in its newest version only.
  void set_dense_region(const std::string& key, std::string message);

  /// Everything newer than `cursor` (greeting first, then the log, the map, the dense regions and the frame), advancing it; waits up to
  /// `timeout` when there is nothing new. Empty on timeout or once closed.
  std::vector<Message> wait_news(Cursor& cursor, std::chrono::milliseconds timeout);
  /// Wakes every waiting client and makes later waits return at once: the server is shutting down.
  void close();
  bool closed() const;

  void client_joined();
  void client_left();
  int clients() const;
  /// Frames set / frames some client was sent (the difference is what slow or absent browsers skipped).
  std::uint64_t frames_set() const;
  std::uint64_t frames_sent() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  Message greeting_, frame_, map_;
  std::uint64_t frame_version_ = 0, map_version_ = 0, frames_sent_ = 0;
  std::vector<Message> log_;
  struct DenseRegion {
    std::uint64_t version = 0;
    Message message;
  };
  std::map<std::string, DenseRegion> dense_;
  std::uint64_t dense_version_ = 0;
  int clients_ = 0;
  bool closed_ = false;
};

/// One server-sent event: "event: <name>\ndata: <data>\n\n" (data must be a single line, as JSON dumps are).
std::string sse_event(std::string_view name, std::string_view data);

}  // namespace varslam::viewer
