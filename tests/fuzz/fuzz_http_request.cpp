// libFuzzer target: raw bytes as one client's connection to `pneumo serve`'s HTTP server
// (serve/bounded_http_server.h): its own stream (reads buffered against a deadline, writes against
// another, the keep-alive loop) under cpp-httplib's request parser and router. One server listens on
// 127.0.0.1, with a status route and a JSON route read as serve reads its bodies; each input is sent
// on a fresh connection (a socket pair the server serves as it serves an accepted socket), the
// sending side then closed, and whatever comes back is read until the server closes the connection. Every input must end in a closed connection
// within the server's bounds, and every answer must start with an HTTP/1.1 status line; a hang, a
// crash or a sanitizer report is a bug for libFuzzer to keep.
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "core/error.h"
#include "fuzz_support.h"
#include "serve/bounded_http_server.h"
#include "serve/request_json.h"

namespace {

using pneumo::serve::BoundedHttpServer;

/// The server, started once per process: it listens (on 127.0.0.1, a port the system picks) so that
/// it runs as serve's does, and the inputs reach it through serve_connection.
BoundedHttpServer& listening_server() {
  static BoundedHttpServer* const running = [] {
    pneumo::serve::ConnectionLimits limits;
    limits.request_read = std::chrono::milliseconds(500);   // short bounds: many inputs a second
    limits.keep_alive_wait = std::chrono::milliseconds(50);
    auto* server = new BoundedHttpServer(limits);   // lives as long as the process
    server->Get("/api/status", [](const httplib::Request&, httplib::Response& res) {
      res.set_content(R"({"state":"ready"})", "application/json");
    });
    server->Post("/api/inflate", [](const httplib::Request& q, httplib::Response& res) {
      const nlohmann::json b = pneumo::serve::read_json_object(q.body, "the body");
      pneumo::serve::check_known_keys(b, "inflate", {"pressure_mmhg", "wall_young_kpa", "preset"});
      res.set_content(b.dump(), "application/json");
    });
    server->set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
      try {
        std::rethrow_exception(ep);
      } catch (const pneumo::InputError&) {
        res.status = 400;
      } catch (...) {
        std::abort();   // only a bad request may throw here: a bug for libFuzzer to keep
      }
    });
    if (server->bind_to_any_port("127.0.0.1") < 0) std::abort();
    std::thread([server] { server->listen_after_bind(); }).detach();
    while (!server->is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return server;
  }();
  return *running;
}

}  // namespace

[[noreturn]] static void fail(const char* why) {
  std::fprintf(stderr, "fuzz_http_request: %s\n", why);
  std::abort();
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pneumo::fuzz::quiet();
  BoundedHttpServer& server = listening_server();
  // A socket pair, not a TCP connection: millions of inputs would use up the loopback's ports.
  int ends[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ends) != 0) fail("socketpair");
  std::thread serving([&server, end = ends[1]] { server.serve_connection(end); });
  // The server answers within its bounds (half a second to read a request, 10 s to write an answer):
  // a connection still open after 15 s is a hang.
  const timeval limit{15, 0};
  ::setsockopt(ends[0], SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
  ::setsockopt(ends[0], SOL_SOCKET, SO_SNDTIMEO, &limit, sizeof limit);
  for (size_t sent = 0; sent < size;) {
    const ssize_t n = ::send(ends[0], data + sent, size - sent, MSG_NOSIGNAL);
    if (n <= 0) break;   // the server may close early (a bad request line): what it sent is still read
    sent += size_t(n);
  }
  ::shutdown(ends[0], SHUT_WR);
  std::string answer;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::recv(ends[0], buffer, sizeof buffer, 0);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == ECONNRESET) break;   // closed with our bytes unread: an answer, of a kind
      fail("the server did not close the connection within 15 s");
    }
    answer.append(buffer, size_t(n));
  }
  ::close(ends[0]);
  serving.join();
  if (!answer.empty() && answer.rfind("HTTP/1.1 ", 0) != 0) fail("an answer without an HTTP/1.1 status line");
  return 0;
}
