#include "core/task_pool.hpp"

#include <stdexcept>
#include <utility>

namespace varslam {

TaskPool::TaskPool(int threads) {
  if (threads < 1) throw std::invalid_argument("TaskPool: threads must be at least 1");
  helpers_.reserve(static_cast<std::size_t>(threads - 1));
  for (int i = 1; i < threads; ++i) helpers_.emplace_back([this] { helper_loop(); });
}

TaskPool::~TaskPool() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  work_ready_.notify_all();
  for (std::thread& t : helpers_) t.join();
}

void TaskPool::run(int n, const std::function<void(int)>& task) {
  if (n <= 0) return;
  if (helpers_.empty() || n == 1) {
    for (int i = 0; i < n; ++i) task(i);
    return;
  }
  std::unique_lock lock(mutex_);
  task_ = &task;
  n_tasks_ = n;
  next_task_ = 0;
  error_ = nullptr;
  ++generation_;
  work_ready_.notify_all();
  drain(lock);
  work_done_.wait(lock, [this] { return running_ == 0; });
  task_ = nullptr;
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
}

void TaskPool::drain(std::unique_lock<std::mutex>& lock) {
  while (next_task_ < n_tasks_) {
    const int i = next_task_++;
    ++running_;
    const std::function<void(int)>& task = *task_;
    lock.unlock();
    std::exception_ptr thrown;
    try {
      task(i);
    } catch (...) {
      thrown = std::current_exception();
    }
    lock.lock();
    if (thrown && !error_) error_ = thrown;
    --running_;
  }
  if (running_ == 0) work_done_.notify_all();
}

void TaskPool::helper_loop() {
  std::unique_lock lock(mutex_);
  std::uint64_t joined = 0;
  for (;;) {
    work_ready_.wait(lock, [&] { return stopping_ || generation_ != joined; });
    if (stopping_) return;
    joined = generation_;
    drain(lock);
  }
}

}  // namespace varslam
