// The thread count fitted to the machine's load (core/thread_count.h): the cores left from the
// kernel's count of runnable tasks, and reading that count from /proc/loadavg's line.
#include <gtest/gtest.h>

#include "core/error.h"
#include "core/thread_count.h"

namespace pneumo {
namespace {

TEST(ThreadCount, CoresLeftAreTheUsableLessTheOtherRunningTasks) {
  // Each sample counts the sampling thread itself: 1 means nobody else runs.
  EXPECT_EQ(cores_left(2, {1, 1, 1, 1, 1}), 2);
  EXPECT_EQ(cores_left(2, {2, 2, 2, 2, 2}), 1);     // one busy process beside us
  EXPECT_EQ(cores_left(8, {4, 4, 4, 4, 4}), 5);
  EXPECT_EQ(cores_left(2, {5, 5, 5, 5, 5}), 1);     // never fewer than one
  EXPECT_EQ(cores_left(4, {0, 0, 0, 0, 0}), 4);     // never more than usable
  // The median: a passing kernel thread or a short burst in one sample does not move it.
  EXPECT_EQ(cores_left(2, {1, 3, 1, 1, 2}), 2);
  EXPECT_EQ(cores_left(4, {3, 1, 3, 3, 9}), 2);
  EXPECT_EQ(cores_left(3, {}), 3);                  // nothing read: every usable core
  EXPECT_EQ(cores_left(0, {1}), 1);
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
