// parallel_for: every task runs exactly once whatever the thread count, and exceptions reach the
// caller.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/parallel.h"

using namespace weft;

TEST(ParallelFor, EveryTaskRunsExactlyOnce) {
  for (int threads : {1, 2, 0}) {
    for (uint64_t count : {uint64_t{0}, uint64_t{1}, uint64_t{7}, uint64_t{10000}}) {
      std::vector<std::atomic<int>> runs(count);
      parallel_for(count, threads, [&](uint64_t task) { runs.at(task).fetch_add(1); });
      for (uint64_t i = 0; i < count; ++i)
        ASSERT_EQ(runs[i].load(), 1) << "task " << i << " of " << count << ", threads " << threads;
    }
  }
}

TEST(ParallelFor, RunsAtMostTheAskedNumberOfTasksAtOnce) {
  for (int threads : {1, 2}) {
    std::atomic<int> running{0}, most{0};
    parallel_for(200, threads, [&](uint64_t) {
      const int now = running.fetch_add(1) + 1;
      int seen = most.load();
      while (now > seen && !most.compare_exchange_weak(seen, now)) {
      }
      std::this_thread::sleep_for(std::chrono::microseconds(50));  // let tasks overlap
      running.fetch_sub(1);
    });
    EXPECT_GE(most.load(), 1);
    EXPECT_LE(most.load(), threads);
  }
}

TEST(ParallelFor, ExceptionsPropagate) {
  for (int threads : {1, 2, 0}) {
    SCOPED_TRACE(threads);
    try {
      parallel_for(1000, threads, [](uint64_t task) {
        if (task == 537) throw Error("task.json", "seed", "bad seed");
      });
      ADD_FAILURE() << "no exception";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), "task.json: field 'seed': bad seed");
    }
    EXPECT_THROW(parallel_for(10, threads, [](uint64_t) { throw std::logic_error("x"); }),
                 std::logic_error);
  }
}

TEST(ParallelFor, HardwareThreadsIsPositive) {
  EXPECT_GE(hardware_threads(), 1);
}

// A request's threads: as asked, or every core for 0 (the options' "0 = all cores").
TEST(ParallelFor, ThreadCountIsTheRequestOrEveryCore) {
  EXPECT_EQ(thread_count(3), 3);
  EXPECT_EQ(thread_count(1), 1);
  EXPECT_EQ(thread_count(0), hardware_threads());
  EXPECT_EQ(thread_count(-1), hardware_threads());
}
