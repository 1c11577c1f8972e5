#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "core/error.hpp"
#include "io/dataset.hpp"

namespace varslam {

FramePrefetcher::FramePrefetcher(const Dataset& ds, std::size_t queue_depth, std::size_t first, std::size_t count,
                                 std::function<void(RgbdFrame&)> prepare)
    : ds_(ds),
      queue_depth_(std::max<std::size_t>(queue_depth, 1)),
      first_(std::min(first, ds.size())),
      end_(first_ + std::min(count, ds.size() - first_)),
      prepare_(std::move(prepare)),
      worker_([this] { run(); }) {}

FramePrefetcher::~FramePrefetcher() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  not_full_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void FramePrefetcher::run() {
  const std::size_t total = end_ - first_;
  const std::size_t max_skips = std::max<std::size_t>(10, total / 10);
  try {
    for (std::size_t i = first_; i < end_; ++i) {
      {
        std::lock_guard lock(mutex_);
        if (stop_) break;
      }
      std::optional<RgbdFrame> frame;
      try {
        frame = ds_.load(i);
      } catch (const InputError& e) {
        std::lock_guard lock(mutex_);
        ++skipped_;
        skipped_frames_.push_back({i, e.what()});
        spdlog::warn("skipping frame {}: {}", i, e.what());
        if (skipped_ > max_skips)
          throw InputError(fmt::format("{}: {} of {} frames could not be read (more than {}); the dataset looks "
                                       "broken. Last error: {}",
                                       ds_.root().string(), skipped_, total, max_skips, e.what()));
        continue;
      }
      if (prepare_) prepare_(*frame);
      std::unique_lock lock(mutex_);
      not_full_.wait(lock, [this] { return stop_ || queue_.size() < queue_depth_; });
      if (stop_) break;
      queue_.push_back(std::move(*frame));
      lock.unlock();
      not_empty_.notify_one();
    }
  } catch (...) {
    std::lock_guard lock(mutex_);
    error_ = std::current_exception();
  }
  {
    std::lock_guard lock(mutex_);
    done_ = true;
  }
  not_empty_.notify_all();
}

std::optional<RgbdFrame> FramePrefetcher::next() {
  std::unique_lock lock(mutex_);
  not_empty_.wait(lock, [this] { return !queue_.empty() || done_; });
  if (!queue_.empty()) {
    RgbdFrame f = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();
    not_full_.notify_one();
    return f;
  }
  if (error_) std::rethrow_exception(error_);
  return std::nullopt;
}

std::size_t FramePrefetcher::skipped() const {
  std::lock_guard lock(mutex_);
  return skipped_;
}

std::vector<SkippedFrame> FramePrefetcher::skipped_frames() const {
  std::lock_guard lock(mutex_);
  return skipped_frames_;
}

}  // namespace varslam
