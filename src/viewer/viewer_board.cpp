#include "viewer/viewer_board.hpp"

namespace varslam::viewer {

void ViewerBoard::set_greeting(std::string message) {
  {
    std::lock_guard lock(mutex_);
    greeting_ = std::make_shared<const std::string>(std::move(message));
  }
  changed_.notify_all();
}

void ViewerBoard::set_frame(std::string message) {
  {
    std::lock_guard lock(mutex_);
    frame_ = std::make_shared<const std::string>(std::move(message));
    ++frame_version_;
  }
  changed_.notify_all();
}

void ViewerBoard::set_map(std::string message) {
  {
    std::lock_guard lock(mutex_);
    map_ = std::make_shared<const std::string>(std::move(message));
    ++map_version_;
  }
  changed_.notify_all();
}

void ViewerBoard::append(std::string message) {
  {
    std::lock_guard lock(mutex_);
    log_.push_back(std::make_shared<const std::string>(std::move(message)));
  }
  changed_.notify_all();
}

void ViewerBoard::set_dense_region(const std::string& key, std::string message) {
  {
    std::lock_guard lock(mutex_);
    dense_[key] = {++dense_version_, std::make_shared<const std::string>(std::move(message))};
  }
  changed_.notify_all();
}

std::vector<Message> ViewerBoard::wait_news(Cursor& cursor, std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  const auto has_news = [&] {
    return closed_ || (greeting_ && !cursor.greeted) || cursor.log < log_.size() || cursor.map < map_version_ ||
           cursor.dense < dense_version_ || cursor.frame < frame_version_;
  };
  changed_.wait_for(lock, timeout, has_news);
  std::vector<Message> out;
  if (closed_) return out;
  if (!cursor.greeted) {
    if (!greeting_) return out;  // nothing is sent before the greeting says what the run is
    out.push_back(greeting_);
    cursor.greeted = true;
  }
  for (; cursor.log < log_.size(); ++cursor.log) out.push_back(log_[cursor.log]);
  if (cursor.map < map_version_) {
    out.push_back(map_);
    cursor.map = map_version_;
  }
  if (cursor.dense < dense_version_) {
    for (const auto& [key, region] : dense_)
      if (region.version > cursor.dense) out.push_back(region.message);
    cursor.dense = dense_version_;
  }
  if (cursor.frame < frame_version_) {
    out.push_back(frame_);
    cursor.frame = frame_version_;
    ++frames_sent_;
  }
  return out;
}

void ViewerBoard::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

bool ViewerBoard::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

void ViewerBoard::client_joined() {
  std::lock_guard lock(mutex_);
  ++clients_;
}

void ViewerBoard::client_left() {
  std::lock_guard lock(mutex_);
  --clients_;
}

int ViewerBoard::clients() const {
  std::lock_guard lock(mutex_);
  return clients_;
}

std::uint64_t ViewerBoard::frames_set() const {
  std::lock_guard lock(mutex_);
  return frame_version_;
}

std::uint64_t ViewerBoard::frames_sent() const {
  std::lock_guard lock(mutex_);
  return frames_sent_;
}

std::string sse_event(std::string_view name, std::string_view data) {
  std::string s;
  s.reserve(name.size() + data.size() + 16);
  s += "event: ";
  s += name;
  s += "\ndata: ";
  s += data;
  s += "\n\n";
  return s;
}

}  // namespace varslam::viewer
