#pragma once
// The one thread of `pneumo serve` that owns the OpenGL context and the solver's state: an EGL or
// OSMesa context is current on one thread, and the shape being solved is not shared. Two kinds of
// work reach it:
//  - short tasks (render a view, pick a point on the skin): queued, run in order, each answered
//    through a future; at most kMaxShortTasks wait, beyond that run() refuses (the server answers
//    503), so views asked for faster than they render cannot take every request thread;
//  - long tasks (a re-inflation), one at a time, latest wins: starting one supersedes the one
//    running, which stops at its next checkpoint, and replaces any still waiting.
// A long task calls checkpoint() at each solver snapshot: the short tasks waiting are answered
// there, so the views keep coming while a solve runs, and a superseded task stops by throwing
// Superseded, which the worker swallows. After a new shape it calls checkpoint_for_views(), which
// also waits briefly for the views a watching page asks for it.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

namespace pneumo::serve {

class SerialWorker {
 public:
  /// Fewer than the server's request threads, so that the status and the controls always find one.
  static constexpr std::size_t kMaxShortTasks = 6;

  /// Thrown by checkpoint() in a long task that a newer one replaced, or when the worker stops.
  struct Superseded : std::exception {
    const char* what() const noexcept override { return "superseded by a newer request"; }
  };
  /// Thrown by run() and start() once the worker stops.
  struct Stopping : std::runtime_error {
    Stopping() : std::runtime_error("the server is stopping") {}
  };
  /// Thrown by run() when kMaxShortTasks already wait.
  struct Busy : std::runtime_error {
    Busy() : std::runtime_error("too many requests waiting; try again") {}
  };

  using LongTask = std::function<void(SerialWorker&, uint64_t generation)>;
  /// Called on the worker with a long task's error (not Superseded), for the status to report.
  using ErrorSink = std::function<void(const std::string&)>;

  /// `at_exit` runs on the worker as it ends (what the thread owns, as a GL context, ends there).
  explicit SerialWorker(ErrorSink on_error = {}, std::function<void()> at_exit = {})
      : on_error_(std::move(on_error)), at_exit_(std::move(at_exit)), thread_([this] {
          loop();
          if (at_exit_) at_exit_();
        }) {}
  ~SerialWorker() { stop(); }
  SerialWorker(const SerialWorker&) = delete;
  SerialWorker& operator=(const SerialWorker&) = delete;

  /// Runs `f` on the worker; its result (or exception) through the future.
  template <class F>
  auto run(F f) -> std::future<decltype(f())> {
    using R = decltype(f());
    auto task = std::make_shared<std::packaged_task<R()>>(std::move(f));
    std::future<R> result = task->get_future();
    {
      std::lock_guard<std::mutex> lock(m_);
      if (stop_) throw Stopping();
      if (short_.size() >= kMaxShortTasks) throw Busy();
      short_.emplace_back([task] { (*task)(); });
      last_short_ = std::chrono::steady_clock::now();
    }
    cv_.notify_one();
    return result;
  }

  /// Queues `task` as the one long task to run next, superseding the one running (and any waiting).
  /// Returns its generation.
  uint64_t start(LongTask task) {
    uint64_t g;
    {
      std::lock_guard<std::mutex> lock(m_);
      if (stop_) throw Stopping();
      g = ++generation_;
      long_ = std::make_pair(g, std::move(task));
    }
    cv_.notify_one();
    return g;
  }

  /// The newest generation started (0: none yet).
  uint64_t generation() const { return generation_.load(); }
  bool superseded(uint64_t generation) const { return generation != generation_.load() || stopping_.load(); }

  /// In a long task, on the worker: answers the short tasks waiting, then throws Superseded when a
  /// newer long task was started meanwhile.
  void checkpoint(uint64_t generation) {
    service();
    if (superseded(generation)) throw Superseded();
  }

  /// A short task arriving within this long of the last one means a page is watching.
  static constexpr std::chrono::seconds kWatchedSeconds{5};
  /// After a view of a new shape, how long checkpoint_for_views waits for the next one.
  static constexpr std::chrono::milliseconds kFollowing{50};

  /// In a long task that just changed what the views show (a new shape): checkpoint(), then, when a
  /// page is watching (a short task came within kWatchedSeconds), waits up to `window` for the views
  /// that change prompts and answers them before the task goes on. A page sees the change at its
  /// next poll and asks at once; without the wait its view would queue behind the solver's next step.
  /// An unwatched task never waits.
  void checkpoint_for_views(uint64_t generation, std::chrono::milliseconds window) {
    using Clock = std::chrono::steady_clock;
    checkpoint(generation);
    {
      std::lock_guard<std::mutex> lock(m_);
      if (Clock::now() - last_short_ > kWatchedSeconds) return;
    }
    // Until the window ends: the first view, then any that follow it closely (a page asks for the
    // laparoscope's view and the body's together), until none comes within kFollowing.
    const auto end = Clock::now() + window;
    auto until = end;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(m_);
        if (!cv_.wait_until(lock, until, [&] { return stop_ || !short_.empty() || long_.has_value(); })) return;
      }
      checkpoint(generation);
      until = std::min(end, Clock::now() + kFollowing);
    }
  }

  /// Stops after the task running: a long one is superseded; short ones waiting are still run.
  void stop() {
    {
      std::lock_guard<std::mutex> lock(m_);
      if (stop_) return;
      stop_ = true;
    }
    stopping_ = true;
    cv_.notify_one();
    if (thread_.joinable()) thread_.join();
  }

 private:
  /// Runs the short tasks waiting when it starts, not those that arrive meanwhile: a steady stream
  /// of views cannot hold a superseded or stopping solve inside a checkpoint.
  void service() {
    std::deque<std::function<void()>> now;
    {
      std::lock_guard<std::mutex> lock(m_);
      now.swap(short_);
    }
    for (auto& f : now) f();   // packaged tasks: each exception goes to its future
  }

  void loop() {
    for (;;) {
      std::optional<std::pair<uint64_t, LongTask>> next;
      {
        std::unique_lock<std::mutex> lock(m_);
        cv_.wait(lock, [&] { return stop_ || !short_.empty() || long_.has_value(); });
        if (stop_ && short_.empty()) return;
        if (!stop_) next.swap(long_);   // its first checkpoint answers the short tasks too
      }
      service();
      if (!next) continue;
      try {
        next->second(*this, next->first);
      } catch (const Superseded&) {
      } catch (const std::exception& e) {
        if (on_error_) on_error_(e.what());
      }
    }
  }

  ErrorSink on_error_;
  std::function<void()> at_exit_;
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> short_;
  std::chrono::steady_clock::time_point last_short_{};   // when the last short task came (guarded by m_)
  std::optional<std::pair<uint64_t, LongTask>> long_;
  std::atomic<uint64_t> generation_{0};
  std::atomic<bool> stopping_{false};
  bool stop_ = false;
  std::thread thread_;   // last: starts once the members above exist
};

}  // namespace pneumo::serve
