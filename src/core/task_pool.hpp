#pragma once
// A few persistent threads that run numbered tasks beside the calling thread (a fork-join per call).
// Our own threads rather than cv::parallel_for_: semantic.num_threads limits OpenCV's pool for the whole process,
// and TBB's synchronisation is invisible to ThreadSanitizer.
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace varslam {

class TaskPool {
 public:
  /// `threads` counts the caller: 1 runs every task inline and starts no thread. At least 1.
  explicit TaskPool(int threads);
  ~TaskPool();
  TaskPool(const TaskPool&) = delete;
  TaskPool& operator=(const TaskPool&) = delete;

  /// Runs task(0) ... task(n - 1), taken in index order by the caller and the helpers, and returns when all
  /// have finished. Tasks must write to disjoint data. The first exception a task throws is rethrown here,
  /// after the other tasks have finished. Not reentrant: one run() at a time per pool.
  void run(int n, const std::function<void(int)>& task);
  int threads() const { return static_cast<int>(helpers_.size()) + 1; }

 private:
  void helper_loop();
  void drain(std::unique_lock<std::mutex>& lock);  // takes tasks until none is left; lock held on entry and exit

  std::mutex mutex_;
  std::condition_variable work_ready_, work_done_;
  const std::function<void(int)>* task_ = nullptr;
  int n_tasks_ = 0;
  int next_task_ = 0;
  int running_ = 0;
  std::uint64_t generation_ = 0;  // one per run(): a helper joins each run once
  bool stopping_ = false;
  std::exception_ptr error_;
  std::vector<std::thread> helpers_;  // last: started after every other member is ready
};

}  // namespace varslam
