#pragma once
// The viewer's HTTP server: the page and scripts from memory, /events as a server-sent-event stream of the board
// (one server thread per browser), and, for a finished run, /frame?i=N (the image of frame N, from a callback).
// Listens on loopback unless told otherwise. Runs on its own threads; stop() (or the destructor) ends every stream.
#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "viewer/viewer_assets.hpp"
#include "viewer/viewer_board.hpp"

namespace httplib {
class Server;
}

namespace varslam::viewer {

struct ServerOptions {
  std::string address = "127.0.0.1";
  int port = 0;         // 0: a free port
  int max_clients = 8;  // live streams at once; one more is answered 503
};

/// JPEG of frame i, or empty when there is no such frame.
using FrameImageSource = std::function<std::optional<std::string>(std::size_t index)>;

class ViewerServer {
 public:
  /// Binds at once: throws InputError naming the address and port when it cannot (the port is taken, say).
  ViewerServer(ViewerBoard& board, std::vector<Asset> assets, const ServerOptions& options,
               FrameImageSource frames = nullptr);
  ~ViewerServer();
  ViewerServer(const ViewerServer&) = delete;
  ViewerServer& operator=(const ViewerServer&) = delete;

  int port() const { return port_; }
  std::string url() const;
  /// Closes the board and the listening socket, ends every stream and joins the server thread. Idempotent.
  void stop();

 private:
  void add_routes(FrameImageSource frames);

  ViewerBoard& board_;
  std::vector<Asset> assets_;
  ServerOptions options_;
  std::unique_ptr<httplib::Server> server_;
  int port_ = 0;
  std::atomic<bool> listen_returned_{false};
  std::thread thread_;
};

}  // namespace varslam::viewer
