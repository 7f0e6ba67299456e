#pragma once
// cpp-httplib's Server with every client's hold on it bounded. Debian's cpp-httplib is a compiled
// library (libcpp-httplib.so): its limits are compiled in, and `#define CPPHTTPLIB_*` before the
// include changes nothing there. Its listen backlog, 5, is one: a burst of connections overflows
// the accept queue, the kernel drops the SYNs beyond it, and their clients retry only after
// seconds (1, 3, 7, ...), so the socket's backlog is raised after bind.
#include <httplib.h>
// glibc's <resolv.h>, which cpp-httplib includes, defines the macro _res, a parameter name in
// Eigen's templates: it must not reach the headers that follow this one.
#undef _res

namespace pneumo::serve {

class BoundedHttpServer : public httplib::Server {
 public:
  /// After bind_to_port or bind_to_any_port: the listening socket's backlog raised from the
  /// library's 5 to SOMAXCONN (Linux applies a second listen() to a listening socket's accept
  /// queue; the system's net.core.somaxconn caps it). False when it could not be.
  bool raise_listen_backlog();
};

}  // namespace pneumo::serve
