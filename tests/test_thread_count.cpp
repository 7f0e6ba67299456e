// The thread count fitted to the machine's load (core/thread_count.h): the cores left from the
// kernel's count of runnable tasks less this process's own, and reading both from /proc.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/thread_count.h"

namespace pneumo {
namespace {

TEST(ThreadCount, CoresLeftAreTheUsableLessTheOtherRunningTasks) {
  // Each sample counts the runnable tasks of other processes: 0 means nobody else runs.
  EXPECT_EQ(cores_left(2, {0, 0, 0, 0, 0}), 2);
  EXPECT_EQ(cores_left(2, {1, 1, 1, 1, 1}), 1);     // one busy process beside us
  EXPECT_EQ(cores_left(8, {3, 3, 3, 3, 3}), 5);
  EXPECT_EQ(cores_left(2, {4, 4, 4, 4, 4}), 1);     // never fewer than one
  EXPECT_EQ(cores_left(4, {-1, -1, -1, 0, 0}), 4);  // never more than usable
  // The median: a passing kernel thread or a short burst in one sample does not move it.
  EXPECT_EQ(cores_left(2, {0, 2, 0, 0, 1}), 2);
  EXPECT_EQ(cores_left(4, {2, 0, 2, 2, 8}), 2);
  EXPECT_EQ(cores_left(3, {}), 3);                  // nothing read: every usable core
  EXPECT_EQ(cores_left(0, {0}), 1);
}

TEST(ThreadCount, TaskStateIsTheLetterAfterTheName) {
  EXPECT_EQ(task_state("4242 (pneumo) R 1 4242 0"), 'R');
  EXPECT_EQ(task_state("4243 (omp worker) S 1 4242 0"), 'S');
  EXPECT_EQ(task_state("4244 (a) b) D 1"), 'D');   // a name may hold ") " itself: the last ')' ends it
  EXPECT_EQ(task_state("4245 (pneumo)"), '?');
  EXPECT_EQ(task_state(""), '?');
}

TEST(ThreadCount, OurOwnSpinningThreadIsNotAnotherProcess) {
  // A thread of ours that spins, as OpenMP's workers do after a loop, is runnable all the while;
  // own_runnable_threads() must see it beside the caller, so that fit_threads_to_load takes it off.
  // Threads of ours that sleep are not runnable and must not be counted: hw + 8 of them wait on a
  // condition variable meanwhile (hw the hardware threads). Counting every thread would give
  // hw + 10 or more; the runnable ones are the caller, the spinner and at most hw − 1 spinning
  // OpenMP workers left by an earlier test in the same process.
  std::atomic<bool> started{false}, stop{false};
  std::mutex m;
  std::condition_variable cv;
  bool release = false;
  std::atomic<int> waiting{0};
  const int hw = std::max(1, int(std::thread::hardware_concurrency())), n_sleepers = hw + 8;
  std::vector<std::thread> sleepers;
  for (int i = 0; i < n_sleepers; ++i)
    sleepers.emplace_back([&] {
      std::unique_lock<std::mutex> lock(m);
      ++waiting;
      cv.wait(lock, [&] { return release; });
    });
  std::thread spinner([&] {
    started = true;
    while (!stop.load(std::memory_order_relaxed)) {
    }
  });
  while (!started || waiting < n_sleepers) std::this_thread::yield();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));   // the sleepers settle in their wait
  const int own = own_runnable_threads();
  stop = true;
  spinner.join();
  {
    std::lock_guard<std::mutex> lock(m);
    release = true;
  }
  cv.notify_all();
  for (std::thread& t : sleepers) t.join();
  EXPECT_GE(own, 2);
  EXPECT_LE(own, hw + 1);
  EXPECT_GE(own_runnable_threads(), 1);   // the caller itself
}

TEST(ThreadCount, RunnableTasksAreTheFourthFieldOfLoadavg) {
  EXPECT_EQ(runnable_tasks("0.72 1.39 1.56 3/612 12345\n"), 3);
  EXPECT_EQ(runnable_tasks("10.00 9.50 8.25 17/2048 99"), 17);
  EXPECT_EQ(runnable_tasks("0.72 1.39 1.56"), -1);
  EXPECT_EQ(runnable_tasks(""), -1);
  EXPECT_EQ(runnable_tasks("garbage"), -1);
}

TEST(ThreadCount, AnExplicitCountOutsideItsRangeIsRefused) {
  EXPECT_THROW(set_thread_count(0), InputError);
  EXPECT_THROW(set_thread_count(kMaxThreads + 1), InputError);
}

}  // namespace
}  // namespace pneumo
