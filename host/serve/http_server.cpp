#include "serve/http_server.h"

#include "serve/bounded_http_server.h"   // cpp-httplib, its _res macro undefined before Eigen comes

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/mime_type.h"
#include "render/gl_context.h"
#include "scene/scene.h"
#include "scene/scene_json.h"
#include "serve/embedded_page.h"
#include "serve/planning_session.h"
#include "serve/request_json.h"
#include "serve/serial_worker.h"

extern char** environ;

namespace pneumo::serve {

namespace fs = std::filesystem;

namespace {

/// A whole number in [lo, hi] (image sizes, label ids): checked on the double, before any cast.
int whole(double d, const char* key, double lo, double hi) {
  if (!(d >= lo && d <= hi && d == std::floor(d)))
    throw InputError(std::string(key) + " must be a whole number from " + std::to_string(int64_t(lo)) + " to " +
                     std::to_string(int64_t(hi)));
  return int(d);
}

double number(const httplib::Request& q, const char* key, double fallback) {
  if (!q.has_param(key)) return fallback;
  const std::string v = q.get_param_value(key);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || !std::isfinite(d)) throw InputError(std::string(key) + ": not a number: " + v);
  return d;
}

Vec3 vec3_of(const nlohmann::json& j, const std::string& what) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
    throw InputError(what + ": three numbers expected");
  const Vec3 v(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
  if (!v.allFinite()) throw InputError(what + ": not finite");
  return v;
}

/// The laparoscope a view asks for: the port from the query, read as a scene's port (its checks,
/// its messages), the dragged aim and the image size.
ScopeRequest scope_request(const httplib::Request& q) {
  nlohmann::json port = {{"name", "view"}};
  if (q.has_param("port")) {
    // The whole port as the scene writes it (lens, up, near plane too), as the page keeps it; its
    // keys are the scene port's, which read_port checks.
    port = read_json_object(q.get_param_value("port"), "port");
    port["name"] = "view";
  } else {
    const Vec3 skin(number(q, "sx", NAN), number(q, "sy", NAN), number(q, "sz", NAN));
    if (!skin.allFinite()) throw InputError("sx, sy, sz (the port's skin point, mm) are required");
    port["skin_point_mm"] = {skin.x(), skin.y(), skin.z()};
    if (q.has_param("label")) {
      port["target_label"] = whole(number(q, "label", 0), "label", 1, 65535);
    } else {
      const Vec3 t(number(q, "tx", NAN), number(q, "ty", NAN), number(q, "tz", NAN));
      if (!t.allFinite()) throw InputError("label or tx, ty, tz (the target) are required");
      port["target_mm"] = {t.x(), t.y(), t.z()};
    }
  }
  for (const auto& [param, key] : {std::pair{"ins", "insertion_mm"}, {"fov", "fov_deg"}, {"obl", "oblique_deg"},
                                   {"roll", "roll_deg"}})
    if (q.has_param(param)) port[key] = number(q, param, 0.0);
  ScopeRequest s;
  s.port = read_port(port, "the view's port");
  s.yaw_deg = number(q, "yaw", 0.0);
  s.pitch_deg = number(q, "pitch", 0.0);
  s.width = whole(number(q, "w", s.width), "w", 16, 1920);
  s.height = whole(number(q, "h", s.height), "h", 16, 1080);
  return s;
}

/// A POST's JSON body: an object whose keys are all among `known` (what the endpoint reads).
nlohmann::json body_json(const httplib::Request& q, const std::vector<std::string>& known) {
  nlohmann::json j = read_json_object(q.body, "the body");
  check_known_keys(j, "the body", known);
  return j;
}

void answer_json(httplib::Response& res, const nlohmann::json& j, int status = 200) {
  res.status = status;
  res.set_content(j.dump(), "application/json");
}

struct PlanRunning : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Requests a second over the whole server, counted in one-second windows.
class RateLimit {
 public:
  int per_second = kMaxRequestsPerSecond;
  bool allow() {
    const int64_t now = std::chrono::duration_cast<std::chrono::seconds>(
                            std::chrono::steady_clock::now().time_since_epoch()).count();
    std::lock_guard<std::mutex> lock(m_);
    if (now != window_) {
      window_ = now;
      count_ = 0;
    }
    return ++count_ <= per_second;
  }

 private:
  std::mutex m_;
  int64_t window_ = 0;
  int count_ = 0;
};

}  // namespace

struct Server::Impl {
  ServeOptions opt;
  std::unique_ptr<PlanningSession> session;   // built and used on the worker's thread only
  std::unique_ptr<SerialWorker> worker;
  BoundedHttpServer http;
  RateLimit rate;
  std::mutex plan_mutex;
  pid_t plan_pid = -1;
  std::thread plan_waiter;
  nlohmann::json plan_status = {{"state", "none"}};

  template <class F>
  auto on_worker(F f) {
    return worker->run(std::move(f)).get();
  }

  void start_plan(const nlohmann::json& body);
  void routes();
};

Server::Server(ServeOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.opt = std::move(options);
  if (s.opt.self_exe.empty()) s.opt.self_exe = fs::read_symlink("/proc/self/exe").string();
  nlohmann::json scene_json = read_scene_json(s.opt.scene_path);
  parse_scene(scene_json, s.opt.scene_path);   // a bad scene is refused before any thread starts
  s.worker = std::make_unique<SerialWorker>(
      [&s](const std::string& message) {
        log::warn("serve: " + message);
        if (s.session) s.session->set_error(message);
      },
      [&s] {
        // The case's GL objects go on the thread that made them, and the process's context is
        // released from it, so that a later worker (a second server in one process) can render.
        const bool rendered = s.session != nullptr;
        s.session.reset();
        if (rendered) shared_gl_context(s.opt.backend).release_current();
      });
  // Built on the worker: the GL context becomes current on the thread that renders with it.
  s.on_worker([&] {
    s.session = std::make_unique<PlanningSession>(scene_json, s.opt.scene_path, s.opt.backend);
    return 0;
  });
  s.worker->start([&s](SerialWorker& w, uint64_t g) { s.session->inflate(InflateRequest{}, w, g); });
  s.routes();
}

Server::~Server() {
  stop();
  impl_->worker->stop();
  {
    std::lock_guard<std::mutex> lock(impl_->plan_mutex);
    if (impl_->plan_pid > 0) ::kill(impl_->plan_pid, SIGTERM);   // a plan's run ends with the server
  }
  if (impl_->plan_waiter.joinable()) impl_->plan_waiter.join();
}

int Server::bind() {
  Impl& s = *impl_;
  if (s.opt.host != "127.0.0.1" && s.opt.host != "localhost" && s.opt.host != "::1")
    log::warn("serve: listening on " + s.opt.host +
              ": anyone who can reach this address can see the case and drive the solver; there is no login");
  int port = s.opt.port;
  if (port == 0) {
    port = s.http.bind_to_any_port(s.opt.host);
    if (port < 0) throw std::runtime_error("serve: cannot bind " + s.opt.host);
  } else if (!s.http.bind_to_port(s.opt.host, port)) {
    throw std::runtime_error("serve: cannot bind " + s.opt.host + ":" + std::to_string(port) +
                             " (in use? choose another with --port)");
  }
  // A burst of views (many tabs, a script) must queue for accept(), not be dropped by the kernel.
  if (!s.http.raise_listen_backlog()) log::warn("serve: cannot raise the listen backlog; bursts of requests may wait");
  return port;
}

void Server::listen() { impl_->http.listen_after_bind(); }
void Server::stop() { impl_->http.stop(); }

void Server::Impl::start_plan(const nlohmann::json& body) {
  if (!body.contains("ports") || !body["ports"].is_array() || body["ports"].size() > 16)
    throw InputError("plan: \"ports\" must be a list of at most 16 ports");
  std::vector<ScopeRequest> ports;
  for (const nlohmann::json& item : body["ports"]) {
    if (!item.is_object()) throw InputError("plan: each port is an object");
    // The page's port: a scene's port (read with a scene port's checks) and the aim it dragged.
    nlohmann::json p = item;
    ScopeRequest q;
    for (const auto& [key, field] : {std::pair{"yaw_deg", &q.yaw_deg}, {"pitch_deg", &q.pitch_deg}}) {
      if (p.contains(key) && !p[key].is_number()) throw InputError(std::string("plan: ") + key + " must be a number");
      *field = p.value(key, 0.0);
      p.erase(key);
    }
    p["name"] = "port_" + std::to_string(ports.size() + 1);   // a file name (the page's names hold spaces)
    q.port = read_port(p, "plan: port " + std::to_string(ports.size() + 1));
    ports.push_back(q);
  }
  nlohmann::json plan = on_worker([&] { return session->plan_json(ports); });
  // The inputs by absolute path: the plan lives in another folder than the scene.
  const Scene scene = parse_scene(plan, opt.scene_path);
  plan["inputs"]["ct"] = fs::absolute(scene.inputs.ct).string();
  if (!scene.inputs.labels.empty()) plan["inputs"]["labels"] = fs::absolute(scene.inputs.labels).string();
  if (!scene.inputs.label_names.empty()) plan["inputs"]["label_names"] = fs::absolute(scene.inputs.label_names).string();
  const fs::path out(opt.out_dir);
  fs::create_directories(out);
  const std::string plan_path = (out / "plan.json").string();
  parse_scene(plan, plan_path);   // every port checked as a scene's, before anything runs
  std::lock_guard<std::mutex> lock(plan_mutex);
  if (plan_pid > 0) throw PlanRunning("plan: a plan's run is still going; wait for it");
  write_text_file_atomic(plan_path, plan.dump(2) + "\n");
  const std::string report_dir = (out / "plan").string();
  std::vector<std::string> args = {opt.self_exe, "-q", "run", plan_path, "--out", report_dir, "--force"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // The run gets the default signal handling back: this process blocks SIGINT and SIGTERM (the
  // watcher takes them) and ignores SIGPIPE (cpp-httplib), and a child inherits both, so the SIGTERM
  // a stopping server sends it would otherwise never arrive.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  for (int sig : {SIGINT, SIGTERM, SIGPIPE}) sigaddset(&defaults, sig);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  pid_t pid = -1;
  const int spawned = posix_spawn(&pid, opt.self_exe.c_str(), nullptr, &attr, argv.data(), environ);
  posix_spawnattr_destroy(&attr);
  if (spawned != 0) throw std::runtime_error("plan: cannot start " + opt.self_exe);
  plan_pid = pid;
  plan_status = {{"state", "running"}, {"scene", plan_path}, {"out", report_dir}};
  if (plan_waiter.joinable()) plan_waiter.join();
  plan_waiter = std::thread([this, pid] {
    int status = 0;
    ::waitpid(pid, &status, 0);
    std::lock_guard<std::mutex> l(plan_mutex);
    plan_pid = -1;
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    plan_status["state"] = code == 0 ? "done" : "failed";
    plan_status["exit_code"] = code;
  });
}

void Server::Impl::routes() {
  rate.per_second = opt.requests_per_second;
  // Each connection has a thread of its own (BoundedHttpServer), far more than views may wait for the
  // worker (SerialWorker::kMaxShortTasks), and each one's hold on it is bounded in time, so the
  // status and the controls always find one.
  http.set_payload_max_length(kMaxBodyBytes);
  const bool loopback = opt.host == "127.0.0.1" || opt.host == "localhost" || opt.host == "::1";
  http.set_pre_routing_handler([this, loopback](const httplib::Request& q, httplib::Response& res) {
    if (!rate.allow()) {
      answer_json(res, {{"error", "too many requests"}}, 429);
      return httplib::Server::HandlerResponse::Handled;
    }
    // Bound to this machine, only this machine's names may reach it: a web page elsewhere that
    // rebinds its own name to 127.0.0.1 (DNS rebinding) would otherwise read the case's images.
    if (loopback) {
      const std::string host = q.get_header_value("Host");
      const std::string name = host.substr(0, host[0] == '[' ? host.find(']') + 1 : host.rfind(':'));
      if (name != "127.0.0.1" && name != "localhost" && name != "[::1]") {
        answer_json(res, {{"error", "Host must be 127.0.0.1, localhost or [::1]"}}, 403);
        return httplib::Server::HandlerResponse::Handled;
      }
    }
    // A POST must say it is JSON: a form or text/plain POST from another site's page (no preflight)
    // is refused, so no page the user visits can drive the solver or start a plan.
    if (q.method == "POST" && q.get_header_value("Content-Type").rfind("application/json", 0) != 0) {
      answer_json(res, {{"error", "a POST body must be application/json"}}, 415);
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  http.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
    try {
      std::rethrow_exception(ep);
    } catch (const InputError& e) {
      answer_json(res, {{"error", e.what()}}, 400);
    } catch (const nlohmann::json::exception& e) {   // a field of the wrong type
      answer_json(res, {{"error", std::string("bad request: ") + e.what()}}, 400);
    } catch (const SerialWorker::Busy& e) {
      answer_json(res, {{"error", e.what()}}, 503);
    } catch (const SerialWorker::Stopping& e) {
      answer_json(res, {{"error", e.what()}}, 503);
    } catch (const StaleView& e) {
      answer_json(res, {{"error", e.what()}}, 409);
    } catch (const PlanRunning& e) {
      answer_json(res, {{"error", e.what()}}, 409);
    } catch (const std::exception& e) {
      answer_json(res, {{"error", e.what()}}, 500);
    }
  });

  for (const EmbeddedPageFile& f : embedded_page()) {
    const std::string route = std::string("/") + (std::string(f.path) == "index.html" ? "" : f.path);
    const std::string* text = &f.source;
    const char* type = mime_type_of(f.path);
    http.Get(route, [text, type](const httplib::Request&, httplib::Response& res) { res.set_content(*text, type); });
  }

  http.Get("/api/status", [this](const httplib::Request&, httplib::Response& res) {
    nlohmann::json j = session->status();
    {
      std::lock_guard<std::mutex> lock(plan_mutex);
      j["plan"] = plan_status;
    }
    j["generation_latest"] = worker->generation();
    answer_json(res, j);
  });
  http.Get("/api/case", [this](const httplib::Request&, httplib::Response& res) {
    answer_json(res, session->case_info());
  });
  http.Post("/api/inflate", [this](const httplib::Request& q, httplib::Response& res) {
    const nlohmann::json b = body_json(q, {"pressure_mmhg", "wall_young_kpa", "preset"});
    InflateRequest r;
    if (b.contains("pressure_mmhg")) r.pressure_mmhg = b["pressure_mmhg"].get<double>();
    if (b.contains("wall_young_kpa")) r.wall_young_kpa = b["wall_young_kpa"].get<double>();
    if (b.contains("preset")) r.preset = b["preset"].get<std::string>();
    session->scene_for(r);   // refused now, with the scene's own message, rather than in the status later
    const uint64_t g = worker->start([this, r](SerialWorker& w, uint64_t gen) { session->inflate(r, w, gen); });
    answer_json(res, {{"generation", g}}, 202);
  });
  http.Get("/api/scope.png", [this](const httplib::Request& q, httplib::Response& res) {
    const ScopeRequest r = scope_request(q);
    res.set_content(on_worker([&] { return session->scope_png(r); }), "image/png");
  });
  http.Get("/api/exterior.png", [this](const httplib::Request& q, httplib::Response& res) {
    const std::string side = q.has_param("side") ? q.get_param_value("side") : "anterior";
    const int w = whole(number(q, "w", 480), "w", 16, 1920), h = whole(number(q, "h", 360), "h", 16, 1080);
    std::vector<Vec3> ports;
    if (q.has_param("ports")) {
      std::stringstream all(q.get_param_value("ports"));
      std::string one;
      while (std::getline(all, one, ';') && ports.size() < 16) {
        Vec3 p;
        if (std::sscanf(one.c_str(), "%lf,%lf,%lf", &p.x(), &p.y(), &p.z()) != 3 || !p.allFinite())
          throw InputError("ports: x,y,z;x,y,z expected");
        ports.push_back(p);
      }
    }
    const bool heat = q.has_param("heat") && q.get_param_value("heat") == "1";
    res.set_content(on_worker([&] { return session->exterior_png(side, w, h, ports, heat); }), "image/png");
  });
  http.Post("/api/pick", [this](const httplib::Request& q, httplib::Response& res) {
    const nlohmann::json b = body_json(q, {"x", "y", "side", "w", "h"});
    const double x = b.value("x", -1.0), y = b.value("y", -1.0);
    const std::string side = b.value("side", std::string("anterior"));
    const int w = whole(b.value("w", 480.0), "w", 16, 1920), h = whole(b.value("h", 360.0), "h", 16, 1080);
    const std::optional<Vec3> p = on_worker([&] { return session->pick(side, w, h, x, y); });
    answer_json(res, {{"skin_point_mm", p ? nlohmann::json{p->x(), p->y(), p->z()} : nlohmann::json()}});
  });
  http.Post("/api/ports", [this](const httplib::Request& q, httplib::Response& res) {
    const nlohmann::json b = body_json(q, {"target_label", "ports", "grid_mm", "top", "region"});
    if (!b.contains("target_label") || !b["target_label"].is_number())
      throw InputError("ports: \"target_label\" (an organ's label id) is required");
    const int target = whole(b["target_label"].get<double>(), "target_label", 1, 65535);
    const double grid_mm = b.value("grid_mm", 20.0);
    if (!(grid_mm >= 5.0 && grid_mm <= 100.0)) throw InputError("grid_mm must be 5 to 100");
    const int top = whole(b.value("top", 10.0), "top", 1, 100);
    std::vector<Vec3> placed;
    if (b.contains("ports")) {
      if (!b["ports"].is_array() || b["ports"].size() > 16) throw InputError("ports: a list of at most 16 points");
      for (const nlohmann::json& p : b["ports"]) placed.push_back(vec3_of(p, "ports"));
    }
    std::optional<RankRegion> region;
    if (b.contains("region") && !b["region"].is_null()) {
      const nlohmann::json& g = b["region"];
      if (!g.is_object()) throw InputError("region: an object {side, w, h, x0, y0, x1, y1} expected");
      check_known_keys(g, "region", {"side", "w", "h", "x0", "y0", "x1", "y1"});
      RankRegion r;
      r.side = g.value("side", std::string("anterior"));
      r.width = whole(g.value("w", 480.0), "region.w", 16, 1920);
      r.height = whole(g.value("h", 360.0), "region.h", 16, 1080);
      for (const auto& [key, field] : {std::pair{"x0", &r.x0}, {"y0", &r.y0}, {"x1", &r.x1}, {"y1", &r.y1}}) {
        if (!g.contains(key) || !g[key].is_number()) throw InputError(std::string("region.") + key + ": a number");
        *field = g[key].get<double>();
      }
      region = r;
    }
    answer_json(res, on_worker([&] { return session->rank_ports(target, placed, grid_mm, top, region); }));
  });
  http.Get("/api/slices.png", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(on_worker([&] { return session->slices_png(); }), "image/png");
  });
  http.Post("/api/plan", [this](const httplib::Request& q, httplib::Response& res) {
    start_plan(body_json(q, {"ports"}));
    std::lock_guard<std::mutex> lock(plan_mutex);
    answer_json(res, plan_status, 202);
  });
  http.Get("/plan/report.html", [this](const httplib::Request&, httplib::Response& res) {
    const fs::path report = fs::path(opt.out_dir) / "plan" / "report.html";
    std::ifstream is(report, std::ios::binary);
    if (!is) return answer_json(res, {{"error", "no plan report yet"}}, 404);
    std::stringstream ss;
    ss << is.rdbuf();
    res.set_content(ss.str(), "text/html; charset=utf-8");
  });
}

int serve_until_signalled(const ServeOptions& options) {
  // SIGINT and SIGTERM go to one watcher thread, which stops the server: blocked here, before any
  // thread starts, so every thread inherits the mask and none is interrupted in the middle of work.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  Server server(options);
  const int port = server.bind();
  std::atomic<bool> done{false};
  std::thread watcher([&] {
    const timespec tick{0, 200 * 1000 * 1000};
    bool stopping = false;
    while (!done) {
      const int sig = sigtimedwait(&signals, nullptr, &tick);
      if (sig == SIGINT || sig == SIGTERM) {
        if (stopping) _exit(128 + sig);   // asked twice: the user will not wait for a clean stop
        log::info("serve: stopping");
        stopping = true;
      }
      // Again at every tick: cpp-httplib's stop() does nothing before listen() runs, and a signal may
      // come while the case still loads.
      if (stopping) server.stop();
    }
  });
  std::printf("serve: http://%s:%d/ (Ctrl-C stops)\n", options.host.c_str(), port);
  std::fflush(stdout);
  server.listen();
  done = true;
  watcher.join();
  return 0;
}

}  // namespace pneumo::serve
