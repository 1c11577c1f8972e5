#include "viewer/viewer_server.hpp"

#include <fmt/format.h>
#include <httplib.h>
#include <spdlog/spdlog.h>

#include <charconv>

#include "core/error.hpp"

namespace varslam::viewer {
namespace {

// A stream with nothing new still writes a comment this often, so a closed browser is noticed.
constexpr auto kKeepAlive = std::chrono::milliseconds(1000);
constexpr auto kWake = std::chrono::milliseconds(200);  // how often a waiting stream checks for shutdown

}  // namespace

ViewerServer::ViewerServer(ViewerBoard& board, std::vector<Asset> assets, const ServerOptions& options,
                           FrameImageSource frames)
    : board_(board), assets_(std::move(assets)), options_(options), server_(std::make_unique<httplib::Server>()) {
  // Each live stream holds a worker thread: enough for max_clients streams and the page's own requests.
  const int threads = options_.max_clients + 4;
  server_->new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<std::size_t>(threads)); };
  // httplib's default also sets SO_REUSEPORT, which lets a second server share a port already in use (connections
  // would be split between the two): address reuse only, so a taken port is refused.
  server_->set_socket_options([](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  add_routes(std::move(frames));
  if (options_.port == 0) {
    port_ = server_->bind_to_any_port(options_.address);
  } else {
    port_ = server_->bind_to_port(options_.address, options_.port) ? options_.port : -1;
  }
  if (port_ <= 0)
    throw InputError(fmt::format("viewer: cannot listen on {}:{} ({}; --viewer-port 0 picks a free port)",
                                 options_.address, options_.port,
                                 options_.port == 0 ? "the address is not this machine's, or no port is free"
                                                    : "the port is taken or the address is not this "
                                                      "machine's"));
  thread_ = std::thread([this] {
    server_->listen_after_bind();
    listen_returned_ = true;
  });
  // httplib's stop() does nothing before its loop runs: wait for it, so a stop() right after start ends it.
  while (!server_->is_running() && !listen_returned_) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

ViewerServer::~ViewerServer() { stop(); }

std::string ViewerServer::url() const {
  const bool v6 = options_.address.find(':') != std::string::npos;
  return fmt::format("http://{}{}{}:{}/", v6 ? "[" : "", options_.address, v6 ? "]" : "", port_);
}

void ViewerServer::stop() {
  board_.close();
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
}

void ViewerServer::add_routes(FrameImageSource frames) {
  for (const Asset& a : assets_) {
    server_->Get(a.url, [&a](const httplib::Request&, httplib::Response& res) {
      res.set_content(a.body, a.content_type.c_str());
      res.set_header("Cache-Control", "no-cache");
    });
  }
  server_->Get("/events", [this](const httplib::Request&, httplib::Response& res) {
    if (board_.clients() >= options_.max_clients) {
      res.status = 503;
      res.set_content("too many viewers connected", "text/plain");
      return;
    }
    board_.client_joined();
    res.set_header("Cache-Control", "no-cache");
    auto cursor = std::make_shared<ViewerBoard::Cursor>();
    auto last_write = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, cursor, last_write](std::size_t, httplib::DataSink& sink) {
          const std::vector<Message> news = board_.wait_news(*cursor, kWake);
          if (board_.closed()) {
            sink.done();
            return true;
          }
          for (const Message& m : news)
            if (!sink.write(m->data(), m->size())) return false;
          const auto now = std::chrono::steady_clock::now();
          if (!news.empty()) {
            *last_write = now;
          } else if (now - *last_write >= kKeepAlive) {
            static constexpr char kComment[] = ": keep-alive\n\n";
            if (!sink.write(kComment, sizeof(kComment) - 1)) return false;
            *last_write = now;
          }
          return true;
        },
        [this](bool) { board_.client_left(); });
  });
  if (frames) {
    server_->Get("/frame", [frames](const httplib::Request& req, httplib::Response& res) {
      // The index is parsed as a number and looked up by the callback: nothing of the request names a file.
      const std::string text = req.get_param_value("i");
      std::size_t index = 0;
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), index);
      std::optional<std::string> jpeg;
      if (ec == std::errc() && end == text.data() + text.size() && !text.empty()) jpeg = frames(index);
      if (!jpeg) {
        res.status = 404;
        res.set_content("no such frame", "text/plain");
        return;
      }
      res.set_content(*jpeg, "image/jpeg");
    });
  }
}

}  // namespace varslam::viewer
