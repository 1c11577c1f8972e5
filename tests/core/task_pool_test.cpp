#include "core/task_pool.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace varslam {
namespace {

TEST(TaskPool, RunsEveryTaskOnceOnEveryRun) {
  for (const int threads : {1, 2, 4}) {
    TaskPool pool(threads);
    EXPECT_EQ(pool.threads(), threads);
    for (int run = 0; run < 200; ++run) {
      const int n = 1 + run % 9;
      std::vector<int> hits(std::size_t(n), 0);
      pool.run(n, [&](int i) { ++hits[std::size_t(i)]; });
      for (int i = 0; i < n; ++i) ASSERT_EQ(hits[std::size_t(i)], 1) << threads << " threads, run " << run;
    }
    pool.run(0, [](int) { FAIL() << "no task to run"; });
  }
}

TEST(TaskPool, HelpersTakeTasksWhileTheCallerIsBusy) {
  TaskPool pool(2);
  std::set<std::thread::id> ran_on;
  std::mutex m;
  std::atomic<int> started{0};
  // Task 0 holds the caller until task 1 has started: only a helper can have started it.
  pool.run(2, [&](int i) {
    {
      const std::lock_guard lock(m);
      ran_on.insert(std::this_thread::get_id());
    }
    ++started;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (started < 2 && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
    (void)i;
  });
  EXPECT_EQ(started.load(), 2);
  EXPECT_EQ(ran_on.size(), 2u);
}

TEST(TaskPool, RethrowsATasksExceptionAfterTheOthersFinished) {
  TaskPool pool(3);
  std::atomic<int> finished{0};
  EXPECT_THROW(pool.run(6,
                        [&](int i) {
                          if (i == 2) throw std::runtime_error("task 2");
                          ++finished;
                        }),
               std::runtime_error);
  EXPECT_EQ(finished.load(), 5);
  // The pool is usable after a failed run.
  std::atomic<int> again{0};
  pool.run(4, [&](int) { ++again; });
  EXPECT_EQ(again.load(), 4);
}

TEST(TaskPool, RejectsNoThreads) { EXPECT_THROW(TaskPool(0), std::invalid_argument); }

}  // namespace
}  // namespace varslam
