#pragma once
// cpp-httplib's Server with every client's hold on it bounded. Debian's cpp-httplib is a compiled
// library (libcpp-httplib.so): its limits are compiled in, and `#define CPPHTTPLIB_*` before the
// include changes nothing there. Its read timeout applies to each recv, so a client that sends one
// byte a second keeps a request thread for as long as it likes, and a dozen such clients take
// every thread of a fixed pool.
// This subclass replaces what serves one connection (process_and_close_socket, a private virtual
// of the library's Server, called for every accepted socket) with a loop over a stream of its own
// (DeadlineStream) that bounds each request's reading and each response's writing in total time,
// and gives each connection a thread of its own up to a cap (ConnectionThreads, its task queue).
// Its listen backlog, 5, is compiled in too: a burst of connections overflows the accept queue,
// the kernel drops the SYNs beyond it, and their clients retry only after seconds (1, 3, 7, ...),
// so the socket's backlog is raised after bind.
#include <httplib.h>
// glibc's <resolv.h>, which cpp-httplib includes, defines the macro _res, a parameter name in
// Eigen's templates: it must not reach the headers that follow this one.
#undef _res

#include <chrono>
#include <cstddef>

namespace pneumo::serve {

struct ConnectionLimits {
  /// A request, head and body, is read whole within this, whatever its pace: a connection's first
  /// request from when a thread takes the connection up, a later one from its first byte. Past it
  /// the connection is closed (after a 400 when its request line had come).
  std::chrono::milliseconds request_read{5000};
  /// A response is written whole within this.
  std::chrono::milliseconds response_write{10000};
  /// How long a kept-alive connection waits for its next request.
  std::chrono::milliseconds keep_alive_wait{1000};
  int max_requests_per_connection = 100;
  /// Connections served at once, each on its own thread; more wait, in order, for a thread.
  std::size_t max_connection_threads = 64;
};

class BoundedHttpServer : public httplib::Server {
 public:
  explicit BoundedHttpServer(ConnectionLimits limits = {});
  /// After bind_to_port or bind_to_any_port: the listening socket's backlog raised from the
  /// library's 5 to SOMAXCONN (Linux applies a second listen() to a listening socket's accept
  /// queue; the system's net.core.somaxconn caps it). False when it could not be.
  bool raise_listen_backlog();
  const ConnectionLimits& limits() const { return limits_; }
  /// Serves one connected socket as an accepted one is served (then closes it), on the caller's
  /// thread, while the server listens: for the fuzz target, which feeds it socket pairs.
  bool serve_connection(socket_t sock) { return process_and_close_socket(sock); }

 private:
  bool process_and_close_socket(socket_t sock) override;

  ConnectionLimits limits_;
};

}  // namespace pneumo::serve
