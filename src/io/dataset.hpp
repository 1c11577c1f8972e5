#pragma once
// RGB-D datasets on disk (TUM RGB-D / Bonn and OpenLORIS-Scene list layouts) behind one interface, and a
// prefetcher that decodes frames ahead on its own thread.
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>
#include <thread>

#include "core/rgbd_frame.hpp"
#include "io/settings.hpp"

namespace varslam {

class Dataset {
 public:
  virtual ~Dataset() = default;
  virtual std::size_t size() const = 0;
  virtual double timestamp(std::size_t i) const = 0;
  /// Decodes frame i; throws InputError naming the file on a missing, unreadable or wrong-sized image.
  /// Safe to call from several threads.
  virtual RgbdFrame load(std::size_t i) const = 0;
  virtual const std::filesystem::path& root() const = 0;
  virtual std::optional<std::filesystem::path> groundtruth() const = 0;  // groundtruth.txt if present
  virtual std::string layout() const = 0;                                // "tum", "openloris"
};

/// Opens a dataset folder, detecting the layout by its list files: associations.txt or rgb.txt + depth.txt
/// (TUM/Bonn), color.txt + aligned_depth.txt (OpenLORIS). Images are checked against settings.camera's size
/// and depth is scaled by settings.depth_factor. Throws InputError on a missing folder or list file, or a bad
/// list line.
std::unique_ptr<Dataset> open_dataset(const std::filesystem::path& dir, const Settings& settings);

/// The settings for a dataset: the explicit file if given, else <dir>/settings.yaml if present, else
/// default_settings() with a warning saying so (depth factor 1000 for an OpenLORIS folder). A settings.yaml that is
/// there but cannot be read (a dangling link, a folder, no permission) is a ConfigError saying why.
Settings settings_for_dataset(const std::filesystem::path& dir, const std::optional<std::filesystem::path>& file);

/// Decodes frames [first, first + count) ahead on its own thread so decoding overlaps with processing.
/// A frame the prefetcher could not read, and why.
struct SkippedFrame {
  std::size_t index = 0;
  std::string reason;
};

class FramePrefetcher {
 public:
  /// `prepare` (optional) runs on each loaded frame on the prefetch thread, e.g. depth registration.
  FramePrefetcher(const Dataset& ds, std::size_t queue_depth = 4, std::size_t first = 0,
                  std::size_t count = SIZE_MAX, std::function<void(RgbdFrame&)> prepare = {});
  ~FramePrefetcher();  // stops and joins
  FramePrefetcher(const FramePrefetcher&) = delete;
  FramePrefetcher& operator=(const FramePrefetcher&) = delete;

  /// The next frame in order; nullopt at the end. Unreadable frames are skipped with a warning and counted;
  /// if more than max(10, 10% of the requested frames) fail, throws InputError (the dataset is broken).
  std::optional<RgbdFrame> next();
  std::size_t skipped() const;
  std::vector<SkippedFrame> skipped_frames() const;

 private:
  void run();

  const Dataset& ds_;
  const std::size_t queue_depth_;
  const std::size_t first_;
  const std::size_t end_;
  const std::function<void(RgbdFrame&)> prepare_;
  mutable std::mutex mutex_;
  std::condition_variable not_full_, not_empty_;
  std::deque<RgbdFrame> queue_;
  std::size_t skipped_ = 0;
  std::vector<SkippedFrame> skipped_frames_;
  bool done_ = false;
  bool stop_ = false;
  std::exception_ptr error_;
  std::thread worker_;  // last: starts after every other member is ready
};

}  // namespace varslam
