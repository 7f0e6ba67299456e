#include "serve/bounded_http_server.h"

#include <sys/socket.h>

namespace pneumo::serve {

bool BoundedHttpServer::raise_listen_backlog() {
  const socket_t sock = svr_sock_;
  return sock != INVALID_SOCKET && ::listen(sock, SOMAXCONN) == 0;
}

}  // namespace pneumo::serve
