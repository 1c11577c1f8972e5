#pragma once
// varslam::viewer::LiveViewer: watch a run in the browser. An observer of the pipeline that copies what it needs on
// the tracking thread (shared image and keypoints, a few counters; the map's keyframe and point lists twice a
// second while a browser is connected) and hands it to its own encoder thread, which reads the map, encodes JPEG
// and JSON at a bounded rate and posts them on the board the server streams from. Nothing on the tracking thread
// waits for the network or the encoder: newer frames replace older ones not yet encoded.
//
//   varslam::viewer::LiveViewer viewer({.server = {.port = 0}});
//   slam.add_observer(viewer);   // prints nothing; viewer.url() is where to point the browser
#include <Eigen/Geometry>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/camera.hpp"
#include "core/trajectory.hpp"
#include "pipeline/events.hpp"
#include "slam/keyframe.hpp"
#include "slam/map_point.hpp"
#include "viewer/dense_layer.hpp"
#include "viewer/viewer_board.hpp"
#include "viewer/viewer_messages.hpp"
#include "viewer/viewer_server.hpp"

namespace varslam::viewer {

struct LiveViewerOptions {
  ServerOptions server;
  double max_frame_rate = 15;                   // frame messages per second at most
  double map_rate = 2;                          // map messages per second at most
  std::string title;                            // what the page shows as the run's name (the dataset)
  std::optional<Trajectory> groundtruth;        // drawn in the map's frame once the live trajectory aligns to it
  std::optional<std::filesystem::path> assets;  // the page's folder (else searched, viewer_assets.hpp)
  DenseLayerOptions dense;                      // the dense map's layer (when the run has dense.enabled)
};

/// What the viewer did, for tests and benchmarks.
struct LiveViewerStats {
  std::uint64_t frames_seen = 0, frames_encoded = 0, frames_sent = 0, maps_encoded = 0;
  double observer_ms_total = 0, observer_ms_max = 0;  // time spent in callbacks on the tracking thread
  std::optional<DenseLayerStats> dense;                // with a dense map
};

class LiveViewer : public Observer {
 public:
  /// Starts the server (InputError when it cannot listen or the page's files are missing) and the encoder.
  explicit LiveViewer(const LiveViewerOptions& options);
  ~LiveViewer() override;
  LiveViewer(const LiveViewer&) = delete;
  LiveViewer& operator=(const LiveViewer&) = delete;

  std::string url() const { return server_.url(); }
  int port() const { return server_.port(); }
  int clients() const { return board_.clients(); }
  LiveViewerStats stats() const;
  /// Ends the streams and the threads (the destructor does it too).
  void stop();

  void on_added(const Pipeline& slam) override;
  void on_depth_registration(const DepthRegistrationEvent& e) override;
  void on_detection(const DetectionEvent& e) override;
  void on_keypoints(const KeypointsEvent& e) override;
  void on_frame(const FrameResult& r) override;
  void on_keyframe_mapped(const slam::KeyframeMapped& m) override;
  void on_loop(const slam::LoopRecord& l) override;
  void on_relocalization(const RelocalizationEvent& e) override;
  void on_finished() override;

 private:
  struct PendingFrame {
    FrameView view;
    cv::Mat image;
    std::shared_ptr<const slam::FrameFeatures> features;
    std::vector<slam::KeypointFate> fate;
    std::vector<cv::Point2f> person_dropped;
  };
  struct PendingMap {
    std::vector<slam::KeyFramePtr> keyframes;
    std::vector<slam::MapPointPtr> points;
    Trajectory live, final_trajectory;
    bool final = false;
  };
  class CallbackTimer;

  void log(std::string_view event, const nlohmann::json& data);
  /// The map's keyframe and point lists (shared, read later) and the trajectories; tracking thread.
  PendingMap snapshot(bool final) const;
  void gather_map();
  void encoder_loop();
  std::string encode_frame(PendingFrame& f) const;
  std::string encode_map(const PendingMap& m) const;

  LiveViewerOptions options_;
  ViewerBoard board_;
  ViewerServer server_;
  const Pipeline* slam_ = nullptr;

  // Tracking thread only.
  PendingFrame building_;
  Trajectory live_;
  std::chrono::steady_clock::time_point last_frame_time_{}, last_map_gather_{};
  double fps_ = 0;
  PinholeCamera camera_;

  // Handed to the encoder (mutex_).
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<PendingFrame> frame_;
  std::optional<PendingMap> map_;
  std::vector<std::string> log_;
  bool stopping_ = false;
  LiveViewerStats stats_;
  std::mutex map_publish_mutex_;  // the final map, once on the board, is never replaced by an older one
  bool final_map_published_ = false;

  std::unique_ptr<DenseLayer> dense_;  // made on the first frame of a run with a dense map (tracking thread)
  mutable std::mutex dense_mutex_;     // dense_ itself, for stats() and stop() from other threads
  std::thread encoder_;
};

}  // namespace varslam::viewer
