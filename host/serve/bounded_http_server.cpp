#include "serve/bounded_http_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <functional>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace pneumo::serve {
namespace {

using Clock = std::chrono::steady_clock;

/// Milliseconds from now until `deadline` for poll(): 0 once it has passed.
int millis_until(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return int(std::clamp<long long>(left, 0, 1000 * 1000));
}

/// Waits until `fd` is ready for `events` or `deadline` passes; true when ready. A signal
/// interrupting poll() resumes the wait towards the same deadline.
bool wait_ready(int fd, short events, Clock::time_point deadline) {
  for (;;) {
    pollfd p{fd, events, 0};
    const int n = ::poll(&p, 1, millis_until(deadline));
    if (n > 0) return true;   // POLLHUP and POLLERR too: the recv or send that follows says which
    if (n == 0 || errno != EINTR) return false;
  }
}

/// "ip" and port of a socket address (IPv4 or IPv6).
void address_text(const sockaddr_storage& a, std::string& ip, int& port) {
  char text[INET6_ADDRSTRLEN] = {};
  if (a.ss_family == AF_INET) {
    const auto& v4 = reinterpret_cast<const sockaddr_in&>(a);
    ::inet_ntop(AF_INET, &v4.sin_addr, text, sizeof text);
    port = ntohs(v4.sin_port);
  } else if (a.ss_family == AF_INET6) {
    const auto& v6 = reinterpret_cast<const sockaddr_in6&>(a);
    ::inet_ntop(AF_INET6, &v6.sin6_addr, text, sizeof text);
    port = ntohs(v6.sin6_port);
  }
  ip = text;
}

/// One accepted connection as cpp-httplib's request parser reads it, with its time bounded in
/// total rather than per recv: each request's bytes must arrive before its read deadline, however
/// they trickle in, and each response must leave before its write deadline. The parser reads its
/// request line and headers a byte at a time: reads come from a buffer filled a recv at a time.
class DeadlineStream : public httplib::Stream {
 public:
  DeadlineStream(socket_t sock, std::chrono::milliseconds write_limit) : sock_(sock), write_limit_(write_limit) {}

  /// A new request: its bytes until `read_deadline`; its response's time starts at its first write.
  void begin_request(Clock::time_point read_deadline) {
    read_deadline_ = read_deadline;
    writing_ = false;
  }

  /// Whether another request starts within `wait` (bytes already buffered count).
  bool next_request_within(std::chrono::milliseconds wait) {
    return buffered() > 0 || wait_ready(sock_, POLLIN, Clock::now() + wait);
  }

  bool is_readable() const override { return buffered() > 0 || wait_ready(sock_, POLLIN, read_deadline_); }
  bool is_writable() const override { return wait_ready(sock_, POLLOUT, write_deadline()); }

  ssize_t read(char* ptr, size_t size) override {
    if (buffered() == 0 && !fill()) return -1;
    const std::size_t n = std::min(size, buffered());
    std::memcpy(ptr, buffer_.data() + begin_, n);
    begin_ += n;
    return ssize_t(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (!writing_) {
      writing_ = true;
      write_deadline_ = Clock::now() + write_limit_;
    }
    for (;;) {
      if (!wait_ready(sock_, POLLOUT, write_deadline_)) return -1;
      const ssize_t n = ::send(sock_, ptr, size, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n >= 0) return n;
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return -1;
    }
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (::getpeername(sock_, reinterpret_cast<sockaddr*>(&a), &len) == 0) address_text(a, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (::getsockname(sock_, reinterpret_cast<sockaddr*>(&a), &len) == 0) address_text(a, ip, port);
  }
  socket_t socket() const override { return sock_; }

 private:
  std::size_t buffered() const { return end_ - begin_; }
  Clock::time_point write_deadline() const { return writing_ ? write_deadline_ : Clock::now() + write_limit_; }

  /// One recv into the empty buffer, waiting no later than the read deadline; false at the
  /// deadline, at the peer's end of stream, or on an error.
  bool fill() {
    for (;;) {
      if (!wait_ready(sock_, POLLIN, read_deadline_)) return false;
      const ssize_t n = ::recv(sock_, buffer_.data(), buffer_.size(), MSG_DONTWAIT);
      if (n > 0) {
        begin_ = 0;
        end_ = std::size_t(n);
        return true;
      }
      if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) return false;
    }
  }

  socket_t sock_;
  std::chrono::milliseconds write_limit_;
  Clock::time_point read_deadline_{};
  Clock::time_point write_deadline_{};
  bool writing_ = false;
  std::array<char, 4096> buffer_{};
  std::size_t begin_ = 0, end_ = 0;
};

/// The server's task queue: each accepted connection runs on a thread of its own, started when no
/// thread is free, up to `max_threads`; beyond that connections wait in order for a free thread.
/// Every connection's hold is bounded (DeadlineStream, the keep-alive wait), so one waits at most
/// that long per connection ahead of it.
class ConnectionThreads : public httplib::TaskQueue {
 public:
  explicit ConnectionThreads(std::size_t max_threads) : max_threads_(std::max<std::size_t>(1, max_threads)) {}
  ~ConnectionThreads() override { shutdown(); }

  void enqueue(std::function<void()> fn) override {
    {
      std::lock_guard<std::mutex> lock(m_);
      jobs_.push_back(std::move(fn));
      if (idle_ < jobs_.size() && threads_.size() < max_threads_) start_thread();
    }
    cv_.notify_one();
  }

  /// Runs what waits, then joins every thread (the library calls it as listen() returns).
  void shutdown() override {
    {
      std::lock_guard<std::mutex> lock(m_);
      if (shutdown_) return;
      shutdown_ = true;
    }
    cv_.notify_all();
    for (std::thread& t : threads_) t.join();   // no thread starts once shutdown_ is set
  }

 private:
  /// A thread the system refuses leaves the connection to the threads there are.
  void start_thread() {
    try {
      threads_.emplace_back([this] { work(); });
    } catch (const std::system_error&) {
    }
  }

  void work() {
    for (;;) {
      std::function<void()> job;
      {
        std::unique_lock<std::mutex> lock(m_);
        ++idle_;
        cv_.wait(lock, [&] { return shutdown_ || !jobs_.empty(); });
        --idle_;
        if (jobs_.empty()) return;
        job = std::move(jobs_.front());
        jobs_.pop_front();
      }
      job();
    }
  }

  const std::size_t max_threads_;
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> jobs_;
  std::vector<std::thread> threads_;
  std::size_t idle_ = 0;   // threads waiting for a job
  bool shutdown_ = false;
};

}  // namespace

BoundedHttpServer::BoundedHttpServer(ConnectionLimits limits) : limits_(limits) {
  new_task_queue = [this] { return new ConnectionThreads(limits_.max_connection_threads); };
}

bool BoundedHttpServer::raise_listen_backlog() {
  const socket_t sock = svr_sock_;
  return sock != INVALID_SOCKET && ::listen(sock, SOMAXCONN) == 0;
}

bool BoundedHttpServer::process_and_close_socket(socket_t sock) {
  DeadlineStream stream(sock, limits_.response_write);
  bool answered = false;
  for (int served = 0; served < limits_.max_requests_per_connection && is_running(); ++served) {
    // The first request's wait is part of its read limit; a later one must start within the
    // keep-alive wait, and its read limit counts from there.
    if (served > 0 && !stream.next_request_within(limits_.keep_alive_wait)) break;
    stream.begin_request(Clock::now() + limits_.request_read);
    const bool last = served + 1 == limits_.max_requests_per_connection;
    bool client_closes = false;
    answered = process_request(stream, last, client_closes, nullptr);
    if (!answered || client_closes) break;
  }
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  return answered;
}

}  // namespace pneumo::serve
