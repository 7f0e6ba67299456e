#pragma once
// `pneumo serve SCENE`: one case resident (planning_session.h) behind a local web page and its HTTP
// API (cpp-httplib). The API, all JSON or PNG:
//   GET  /                      the page (index.html, app.js, style.css, embedded)
//   GET  /api/case              what does not change: the scene's ports and the label map's ids with
//                               their names (read once)
//   GET  /api/status            settings, solve progress, the last equilibrium's figures, the plan's
//                               state
//   POST /api/inflate           {"pressure_mmhg", "wall_young_kpa", "preset"}: a re-inflation from the
//                               last equilibrium; latest wins (202 with its generation)
//   GET  /api/scope.png         the laparoscope at a port: port={...} (a scene's port, as JSON) or
//                               sx,sy,sz (skin point, CT as given, mm) and label or tx,ty,tz (target);
//                               ins, fov, obl, roll over it; yaw, pitch (the dragged aim), w, h
//   GET  /api/exterior.png      side=anterior|left, w, h, ports=x,y,z;x,y,z (marked), heat=1 (the last
//                               port ranking's scores drawn on the skin)
//   POST /api/ports             {"target_label", "ports": [[x,y,z], ...] (placed, CT as given), "grid_mm",
//                               "top", "region": {side, w, h, x0, y0, x1, y1}}: candidate ports ranked on
//                               the shape shown (docs/ports.md), within the region painted on the last
//                               body view when given (409 for another view), the best `top` of the
//                               table `pneumo ports` writes
//   POST /api/pick              {"x", "y", "side", "w", "h"} on the last exterior view → {"skin_point_mm"}
//                               (CT as given); 409 when that view is no longer the last drawn
//   GET  /api/slices.png        axial, coronal, sagittal before and after
//   POST /api/plan              {"ports": [...]}: writes OUT/plan.json and starts `pneumo run` on it
//                               into OUT/plan (202); its report at GET /plan/report.html
// Safe by default: it binds 127.0.0.1 unless told otherwise (and warns when not), and then answers
// only Hosts naming this machine (403) and POSTs declared JSON (415), so other web pages cannot drive
// it; no file path or scene text is taken from a client (the plan's ports are checked as a scene's);
// JSON (bodies, the `port` parameter) is read as scene files are, and a key given twice, bytes after
// the value, or a key the endpoint does not read is refused (400, naming it) rather than ignored;
// request bodies up to kMaxBodyBytes (413); at most kMaxRequestsPerSecond requests a second (429);
// views queue on one worker (503 when SerialWorker::kMaxShortTasks wait); SIGINT and SIGTERM stop it
// cleanly, a plan's run with it.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "render/gl_context.h"

namespace pneumo::serve {

inline constexpr std::size_t kMaxBodyBytes = 64 * 1024;
inline constexpr int kMaxRequestsPerSecond = 200;

struct ServeOptions {
  std::string scene_path;
  std::string host = "127.0.0.1";
  int port = 8080;                 // 0: any free port (the tests')
  std::string out_dir = "out/serve";   // where plans and their reports go
  GlBackend backend = GlBackend::Auto;
  std::string self_exe;            // the pneumo binary a plan runs (default /proc/self/exe)
  int requests_per_second = kMaxRequestsPerSecond;
};

class Server {
 public:
  /// Loads the case (roles, mesh; the renderer) and starts the first inflation at the scene's
  /// settings. InputError for a bad scene.
  explicit Server(ServeOptions options);
  ~Server();
  /// Binds; returns the port (the one asked for, or the free one picked for port 0). Throws
  /// std::runtime_error when the address cannot be bound.
  int bind();
  /// Serves until stop() (another thread, or the signal watcher).
  void listen();
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// `pneumo serve`: the server until SIGINT or SIGTERM; returns the exit code.
int serve_until_signalled(const ServeOptions& options);

}  // namespace pneumo::serve
