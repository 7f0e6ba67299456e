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

// After a new shape, a long task waits briefly for the views a watching page asks: a view requested
// within the window is answered before the task goes on (here, before a step of 400 ms it would
// otherwise queue behind); with nobody watching (no short task for kWatchedSeconds) it does not wait.
TEST(SerialWorker, ANewShapeWaitsForTheViewsOfAWatchingPageOnly) {
  using namespace std::chrono;
  {
    SerialWorker unwatched;
    std::atomic<int64_t> waited_ms{-1};
    std::atomic<bool> done{false};
    unwatched.start([&](SerialWorker& worker, uint64_t g) {
      const auto t = steady_clock::now();
      worker.checkpoint_for_views(g, milliseconds(300));
      waited_ms = duration_cast<milliseconds>(steady_clock::now() - t).count();
      done = true;
    });
    wait_until(done);
    EXPECT_LT(waited_ms.load(), 150) << "an unwatched solve does not wait";
  }
  SerialWorker w;
  w.run([] { return 0; }).get();   // the page's earlier view: it is watching
  std::atomic<bool> at_news{false}, step_done{false};
  w.start([&](SerialWorker& worker, uint64_t g) {
    at_news = true;
    worker.checkpoint_for_views(g, milliseconds(2000));
    std::this_thread::sleep_for(milliseconds(400));   // the solver's next step
    step_done = true;
  });
  wait_until(at_news);
  ASSERT_TRUE(at_news);
  std::this_thread::sleep_for(milliseconds(50));   // the page's poll sees the shape, then asks
  const bool before_the_step = w.run([&] { return !step_done.load(); }).get();
  EXPECT_TRUE(before_the_step) << "the view of the new shape waited for the solver's next step";
  w.stop();
}
