// The worker of `pneumo serve` (host/serve/serial_worker.h), without a server: short tasks answered
// in order and inside a running long task's checkpoints; a newer long task supersedes the running one
// at its next checkpoint; a long task's error reaches the sink; a queue beyond kMaxShortTasks is
// refused; stop() returns while a long task runs.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "serve/serial_worker.h"

using pneumo::serve::SerialWorker;

namespace {

/// A long task that loops on checkpoints until superseded, noting that it saw it.
SerialWorker::LongTask looping(std::atomic<bool>& running, std::atomic<bool>& superseded) {
  return [&running, &superseded](SerialWorker& w, uint64_t g) {
    running = true;
    try {
      for (;;) {
        w.checkpoint(g);
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    } catch (const SerialWorker::Superseded&) {
      superseded = true;
      throw;
    }
  };
}

void wait_until(const std::atomic<bool>& flag) {
  for (int k = 0; k < 5000 && !flag; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

}  // namespace

TEST(SerialWorker, ShortTasksRunInOrderAndInsideALongOne) {
  SerialWorker w;
  std::vector<int> order;
  auto a = w.run([&] { order.push_back(1); return 1; });
  auto b = w.run([&] { order.push_back(2); return 2; });
  EXPECT_EQ(a.get() + b.get(), 3);
  EXPECT_EQ(order, (std::vector<int>{1, 2}));

  std::atomic<bool> running{false}, superseded{false};
  w.start(looping(running, superseded));
  wait_until(running);
  ASSERT_TRUE(running);
  const std::thread::id inside = w.run([] { return std::this_thread::get_id(); }).get();   // answered mid-task
  EXPECT_NE(inside, std::this_thread::get_id());
  w.stop();
  EXPECT_TRUE(superseded) << "stop() supersedes the running long task";
}

TEST(SerialWorker, TheLatestLongTaskWinsAndErrorsReachTheSink) {
  std::string error;
  SerialWorker w([&](const std::string& e) { error = e; });
  std::atomic<bool> first_running{false}, first_superseded{false}, second_running{false}, second_superseded{false};
  const uint64_t g1 = w.start(looping(first_running, first_superseded));
  wait_until(first_running);
  const uint64_t g2 = w.start(looping(second_running, second_superseded));
  EXPECT_GT(g2, g1);
  EXPECT_TRUE(w.superseded(g1));
  EXPECT_FALSE(w.superseded(g2));
  wait_until(second_running);
  EXPECT_TRUE(first_superseded);
  EXPECT_TRUE(second_running);
  w.start([](SerialWorker&, uint64_t) { throw std::runtime_error("diverged: lower the pressure"); });
  for (int k = 0; k < 5000 && error.empty(); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(error, "diverged: lower the pressure");
  EXPECT_TRUE(second_superseded);
}

TEST(SerialWorker, AFullQueueIsRefusedAndAStoppedWorkerTakesNothing) {
  SerialWorker w;
  std::atomic<bool> release{false};
  auto blocker = w.run([&] {
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return 0;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));   // the blocker is running, not waiting
  std::vector<std::future<int>> waiting;
  for (std::size_t k = 0; k < SerialWorker::kMaxShortTasks; ++k) waiting.push_back(w.run([] { return 7; }));
  EXPECT_THROW(w.run([] { return 0; }), SerialWorker::Busy);
  release = true;
  for (auto& f : waiting) EXPECT_EQ(f.get(), 7);
  blocker.get();
  w.stop();
  EXPECT_THROW(w.run([] { return 0; }), SerialWorker::Stopping);
  EXPECT_THROW(w.start([](SerialWorker&, uint64_t) {}), SerialWorker::Stopping);
}
