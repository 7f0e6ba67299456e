// `pneumo serve`'s HTTP API (host/serve/http_server.h) on the small phantom at `preview`, through a
// real HTTP client on a real socket: the page and its files, the laparoscope's and the body's views
// (PNG), a click on the skin placing a port where the skin is, a re-inflation from the last
// equilibrium with latest-wins, bad input answered 400 with the reason, the body and rate limits,
// a burst of views all answered and clients that drip their requests dropped while the status still
// answers, JSON with an unknown or duplicate key or trailing bytes refused, the scene read as the
// CLI reads it, and a server that stops promptly in the middle of a solve.
#include <gtest/gtest.h>

#include <httplib.h>
#undef _res   // glibc's resolv.h macro, a parameter name in Eigen (host/serve/http_server.cpp says why)

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "cli_test_support.h"
#include "core/error.h"
#include "core/progress.h"
#include "phantom/phantom.h"
#include "scene/scene.h"
#include "serve/http_server.h"
#include "stb_image_support.h"

using namespace pneumo;
using testing_support::ScratchDir;

namespace {

using Clock = std::chrono::steady_clock;

/// The small phantom's case at `preview` (12 mm cubes: a solve of seconds), its scene's first port.
std::string write_case(const ScratchDir& dir) {
  write_phantom_case(make_phantom(PhantomSize::Small), PhantomSize::Small, dir.path().string());
  nlohmann::json j = nlohmann::json::parse(testing_support::slurp(dir.file("scene.json")));
  j["preset"] = "preview";
  std::ofstream(dir.file("serve_scene.json")) << "// The small phantom at preview: a scene written by hand may hold comments.\n"
                                              << j.dump(2);
  return dir.file("serve_scene.json");
}

class ServeApi : public ::testing::Test {
 protected:
  void start(int requests_per_second = serve::kMaxRequestsPerSecond) {
    Progress::set_enabled(false);
    serve::ServeOptions o;
    o.scene_path = write_case(dir_);
    o.port = 0;
    o.out_dir = dir_.file("serve_out");
    o.requests_per_second = requests_per_second;
    o.self_exe = PNEUMO_CLI_PATH;   // a plan runs `pneumo run`; /proc/self/exe here is this test binary
    server_ = std::make_unique<serve::Server>(o);
    port_ = server_->bind();
    listener_ = std::thread([this] { server_->listen(); });
    client_ = std::make_unique<httplib::Client>("127.0.0.1", port_);
    client_->set_read_timeout(120, 0);
  }
  void TearDown() override {
    if (server_) server_->stop();
    if (listener_.joinable()) listener_.join();
    server_.reset();
  }
  nlohmann::json status() { return nlohmann::json::parse(client_->Get("/api/status")->body); }
  /// Polls until the solve of `generation` or a later one has ended; false after `seconds`.
  bool wait_solved(uint64_t generation, double seconds = 180) {
    const auto t0 = Clock::now();
    while (std::chrono::duration<double>(Clock::now() - t0).count() < seconds) {
      const nlohmann::json s = status();
      if (!s["solving"].get<bool>() && s.value("generation", uint64_t(0)) >= generation) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    return false;
  }
  static std::string scope_query() { return "/api/scope.png?sx=0&sy=110&sz=-20&label=5&ins=45&obl=30&w=160&h=120"; }

  ScratchDir dir_;
  std::unique_ptr<serve::Server> server_;
  std::thread listener_;
  int port_ = 0;
  std::unique_ptr<httplib::Client> client_;
};

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// A blocking TCP connection to 127.0.0.1:port; -1 when refused.
int connect_local(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(uint16_t(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd >= 0 && ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) return fd;
  if (fd >= 0) ::close(fd);
  return -1;
}

/// Whether the server has closed `fd` (end of stream or reset; what it answered before is read
/// and dropped), without waiting.
bool closed_by_server(int fd) {
  pollfd p{fd, POLLIN, 0};
  while (::poll(&p, 1, 0) > 0) {
    char buf[512];
    const ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
    if (n <= 0) return true;
  }
  return false;
}

/// /api/status on a connection of its own: its HTTP status (-1: no answer) and how long it took.
std::pair<int, double> timed_status(int port) {
  httplib::Client c("127.0.0.1", port);
  c.set_connection_timeout(5, 0);
  c.set_read_timeout(5, 0);
  const auto t0 = Clock::now();
  const auto r = c.Get("/api/status");
  return {r ? r->status : -1, seconds_since(t0)};
}

bool is_png(const std::string& bytes) { return bytes.size() > 8 && bytes.compare(1, 3, "PNG") == 0; }

int png_width(const std::string& bytes) {
  int w = 0, h = 0, c = 0;
  unsigned char* px = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()), int(bytes.size()),
                                            &w, &h, &c, 3);
  if (px) stbi_image_free(px);
  return w;
}

/// Mean absolute difference of two PNGs' RGB values (0–255), 255 when they differ in size.
double mean_abs_difference(const std::string& a, const std::string& b) {
  int wa = 0, ha = 0, wb = 0, hb = 0, c = 0;
  unsigned char* pa = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(a.data()), int(a.size()), &wa, &ha, &c, 3);
  unsigned char* pb = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(b.data()), int(b.size()), &wb, &hb, &c, 3);
  double d = 255.0;
  if (pa && pb && wa == wb && ha == hb) {
    double sum = 0.0;
    for (int k = 0; k < wa * ha * 3; ++k) sum += std::abs(int(pa[k]) - int(pb[k]));
    d = sum / (wa * ha * 3.0);
  }
  if (pa) stbi_image_free(pa);
  if (pb) stbi_image_free(pb);
  return d;
}

}  // namespace

// Compared: what the page and its views must be (the page's own files, PNGs of the asked size), the
// pick's truth (a ray through the middle of the anterior view meets the skin in front: on the CT as
// given, the phantom's anterior skin lies at y ≈ 100–120 mm on the midline), and a re-inflation
// whose figures move the way physics says (12 → 6 mmHg: a smaller cavity, a lower rise).
TEST_F(ServeApi, PageViewsPickAndAWarmReinflation) {
  ASSERT_NO_FATAL_FAILURE(start());
  const auto page = client_->Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<script src=\"/app.js\">"), std::string::npos);
  EXPECT_EQ(client_->Get("/app.js")->status, 200);
  EXPECT_EQ(client_->Get("/style.css")->status, 200);
  ASSERT_TRUE(wait_solved(1));
  nlohmann::json s = status();
  EXPECT_TRUE(s["converged"].get<bool>()) << s.dump();
  EXPECT_NEAR(s["pressure_mmhg"].get<double>(), 12.0, 1e-6);
  const double rise12 = s["anterior_rise_mm"], cavity12 = s["cavity_volume_ml"];
  EXPECT_GT(rise12, 10.0);
  // The page starts from the scene's ports and offers the label map's organs by name, read once
  // from /api/case; the status, polled, carries neither.
  EXPECT_FALSE(s.contains("ports") || s.contains("labels")) << s.dump();
  const nlohmann::json c = nlohmann::json::parse(client_->Get("/api/case")->body);
  ASSERT_FALSE(c["ports"].empty());
  EXPECT_EQ(c["ports"][0]["skin_point_mm"], nlohmann::json({0.0, 110.0, -20.0}));
  bool liver = false;
  for (const nlohmann::json& l : c["labels"]) liver |= l["id"] == 5 && l["name"] == "liver";
  EXPECT_TRUE(liver) << c["labels"].dump();

  const auto scope = client_->Get(scope_query().c_str());
  ASSERT_TRUE(scope);
  ASSERT_EQ(scope->status, 200) << scope->body;
  ASSERT_TRUE(is_png(scope->body));
  EXPECT_EQ(png_width(scope->body), 160);
  // The same port as the page sends it, whole (a scene's port as JSON): the same view.
  const auto as_json = client_->Get(
      "/api/scope.png?w=160&h=120&port=" +
      httplib::detail::encode_query_param(R"({"skin_point_mm":[0,110,-20],"target_label":5,"insertion_mm":45,"oblique_deg":30})"));
  ASSERT_EQ(as_json->status, 200) << as_json->body;
  EXPECT_EQ(as_json->body, scope->body);
  const auto ext = client_->Get("/api/exterior.png?side=anterior&w=200&h=150&ports=0,110,-20");
  ASSERT_EQ(ext->status, 200) << ext->body;
  EXPECT_EQ(png_width(ext->body), 200);
  EXPECT_EQ(client_->Get("/api/slices.png")->status, 200);

  const auto pick = client_->Post("/api/pick", R"({"x": 100, "y": 75, "side": "anterior", "w": 200, "h": 150})",
                                  "application/json");
  ASSERT_EQ(pick->status, 200) << pick->body;
  const nlohmann::json p = nlohmann::json::parse(pick->body)["skin_point_mm"];
  ASSERT_TRUE(p.is_array()) << pick->body;
  EXPECT_NEAR(p[0].get<double>(), 0.0, 40.0);
  EXPECT_GT(p[1].get<double>(), 90.0);
  EXPECT_LT(p[1].get<double>(), 130.0);
  const auto sky = client_->Post("/api/pick", R"({"x": 2, "y": 2, "side": "anterior", "w": 200, "h": 150})",
                                 "application/json");
  EXPECT_TRUE(nlohmann::json::parse(sky->body)["skin_point_mm"].is_null()) << "a corner of the view holds no skin";
  // A click on a view that is no longer the last one drawn (another side) is refused, not misplaced.
  EXPECT_EQ(client_->Post("/api/pick", R"({"x": 100, "y": 75, "side": "left", "w": 200, "h": 150})",
                          "application/json")->status, 409);

  // Port ranking for the liver on the inflated shape, the scene's port placed: the best few of the
  // table `pneumo ports` writes, on the anterior skin; then the same scores drawn on the body's view.
  const auto ranked = client_->Post("/api/ports", R"({"target_label": 5, "ports": [[0, 110, -20]], "top": 3})",
                                    "application/json");
  ASSERT_EQ(ranked->status, 200) << ranked->body;
  const nlohmann::json t = nlohmann::json::parse(ranked->body);
  EXPECT_EQ(t["target"]["name"], "liver");
  EXPECT_LE(t["candidates"].size(), 3u);
  EXPECT_GT(t["candidates_total"].get<int>(), 3);
  ASSERT_GT(t["feasible_candidates"].get<int>(), 0) << ranked->body;
  const nlohmann::json& best = t["candidates"][0];
  EXPECT_TRUE(best["feasible"].get<bool>());
  EXPECT_GT(best["score"].get<double>(), 0.0);
  ASSERT_TRUE(best["skin_point_mm"].is_array());
  EXPECT_GT(best["skin_point_mm"][1].get<double>(), 60.0) << "a port on the anterior skin";
  EXPECT_TRUE(best["terms"].contains("triangulation")) << "scored against the port already placed";
  const auto heat = client_->Get("/api/exterior.png?side=anterior&w=200&h=150&ports=0,110,-20&heat=1");
  ASSERT_EQ(heat->status, 200) << heat->body;
  EXPECT_NE(heat->body, client_->Get("/api/exterior.png?side=anterior&w=200&h=150&ports=0,110,-20")->body);
  // Within a region painted on that view (its left half): fewer candidates, none from elsewhere;
  // a region painted on another view than the last drawn is refused.
  const auto half = client_->Post(
      "/api/ports",
      R"({"target_label": 5, "top": 100, "region": {"side": "anterior", "w": 200, "h": 150, "x0": 0, "y0": 0, "x1": 100, "y1": 150}})",
      "application/json");
  ASSERT_EQ(half->status, 200) << half->body;
  const nlohmann::json th = nlohmann::json::parse(half->body);
  EXPECT_GT(th["candidates_total"].get<int>(), 0);
  EXPECT_LT(th["candidates_total"].get<int>(), t["candidates_total"].get<int>());
  EXPECT_EQ(client_->Post("/api/ports",
                          R"({"target_label": 5, "region": {"side": "left", "w": 200, "h": 150, "x0": 0, "y0": 0, "x1": 9, "y1": 9}})",
                          "application/json")->status, 409);
  const auto absent = client_->Post("/api/ports", R"({"target_label": 999})", "application/json");
  EXPECT_EQ(absent->status, 400);
  EXPECT_NE(absent->body.find("holds no voxel"), std::string::npos) << absent->body;

  const auto again = client_->Post("/api/inflate", R"({"pressure_mmhg": 6})", "application/json");
  ASSERT_EQ(again->status, 202) << again->body;
  const uint64_t g = nlohmann::json::parse(again->body)["generation"];
  ASSERT_TRUE(wait_solved(g));
  s = status();
  EXPECT_TRUE(s["converged"].get<bool>()) << s.dump();
  EXPECT_NEAR(s["pressure_mmhg"].get<double>(), 6.0, 1e-6);
  EXPECT_LT(s["anterior_rise_mm"].get<double>(), rise12);
  EXPECT_LT(s["cavity_volume_ml"].get<double>(), cavity12);
  const auto scope6 = client_->Get(scope_query().c_str());
  EXPECT_NE(scope6->body, scope->body) << "the view follows the new shape";

  // A plan: each port read as a scene's; one aimed by dragging (yaw 20°) keeps that aim as a target
  // point on the dragged axis, the other its organ. A port the scene would refuse is refused first.
  const auto bad = client_->Post(
      "/api/plan", R"({"ports": [{"skin_point_mm": [0, 110, -20], "target_label": 5, "fov_deg": 200}]})",
      "application/json");
  EXPECT_EQ(bad->status, 400);
  EXPECT_NE(bad->body.find("plan: port 1: port.fov_deg = 200"), std::string::npos) << bad->body;
  const auto plan = client_->Post("/api/plan", R"({"ports": [
      {"skin_point_mm": [0, 110, -20], "target_label": 5, "insertion_mm": 45, "yaw_deg": 20},
      {"skin_point_mm": [0, 110, -20], "target_label": 5, "insertion_mm": 45}]})", "application/json");
  ASSERT_EQ(plan->status, 202) << plan->body;
  const nlohmann::json written = nlohmann::json::parse(testing_support::slurp(dir_.file("serve_out/plan.json")));
  const nlohmann::json& ports = written["render"]["ports"];
  ASSERT_EQ(ports.size(), 2u);
  EXPECT_TRUE(ports[0]["target_label"].is_null()) << ports[0].dump();
  ASSERT_TRUE(ports[0]["target_mm"].is_array()) << ports[0].dump();
  EXPECT_EQ(ports[1]["target_label"], 5);
  EXPECT_EQ(ports[1]["insertion_mm"], 45.0);
  // The saved point is on the dragged axis: the plan's port, aimed at it without a drag, sees what
  // the dragged view saw (the point goes back to the CT as given and forwards again).
  const nlohmann::json& aimed = ports[0]["target_mm"];
  const std::string dragged = client_->Get("/api/scope.png?sx=0&sy=110&sz=-20&label=5&ins=45&yaw=20&w=160&h=120")->body;
  const std::string saved = client_->Get(("/api/scope.png?sx=0&sy=110&sz=-20&ins=45&w=160&h=120&tx=" +
                                          std::to_string(aimed[0].get<double>()) + "&ty=" + std::to_string(aimed[1].get<double>()) +
                                          "&tz=" + std::to_string(aimed[2].get<double>())).c_str())->body;
  const std::string undragged = client_->Get("/api/scope.png?sx=0&sy=110&sz=-20&label=5&ins=45&w=160&h=120")->body;
  EXPECT_LT(mean_abs_difference(dragged, saved), 2.0);
  EXPECT_GT(mean_abs_difference(dragged, undragged), 5.0) << "a 20° turn shows another part of the cavity";
  EXPECT_EQ(written["load"]["pressure_mmhg"], 6.0);
}

// Latest wins: two requests in a row, the first superseded before it ends; the status ends at the
// second's pressure, under the second's generation. Then a preset that changes the mesh. Bad input is refused with its reason, before any
// work: a pressure beyond 40 mmHg, an unknown preset, a stiffness the scene's limits refuse, a view
// without a skin point, a field of view of 200°, a body that is no JSON object, one that is not
// declared JSON (415), a Host other than this machine's (403), and one over the body limit (413).
TEST_F(ServeApi, LatestWinsAndBadInputIsRefusedWithItsReason) {
  ASSERT_NO_FATAL_FAILURE(start());
  const auto a = client_->Post("/api/inflate", R"({"pressure_mmhg": 20})", "application/json");
  const auto b = client_->Post("/api/inflate", R"({"pressure_mmhg": 8})", "application/json");
  ASSERT_EQ(a->status, 202);
  ASSERT_EQ(b->status, 202);
  const uint64_t gb = nlohmann::json::parse(b->body)["generation"];
  EXPECT_GT(gb, nlohmann::json::parse(a->body)["generation"].get<uint64_t>());
  ASSERT_TRUE(wait_solved(gb));
  const nlohmann::json s = status();
  EXPECT_EQ(s["generation"].get<uint64_t>(), gb);
  EXPECT_NEAR(s["pressure_mmhg"].get<double>(), 8.0, 1e-6);

  const auto refused = [&](const char* path, const std::string& body, const char* says) {
    const auto r = body.empty() ? client_->Get(path) : client_->Post(path, body, "application/json");
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 400) << path << " " << body;
    EXPECT_NE(r->body.find(says), std::string::npos) << r->body;
  };
  refused("/api/inflate", R"({"pressure_mmhg": 55})", "pressure_mmhg must be 0 to 40");
  refused("/api/inflate", R"({"preset": "fastest"})", "preset must be");
  refused("/api/inflate", R"({"wall_young_kpa": -3})", "wall_young_kpa");
  refused("/api/inflate", R"([1, 2])", "must be a JSON object");
  refused("/api/inflate", R"({"pressure_mmhg": "high"})", "bad request");
  refused("/api/scope.png?label=5", "", "sx, sy, sz");
  refused("/api/scope.png?sx=0&sy=110&sz=-20&label=5&fov=200", "", "fov_deg");
  // Another site's page can send a form or text/plain without asking first: refused (415), and a
  // Host that is not this machine's name (DNS rebinding) gets 403.
  EXPECT_EQ(client_->Post("/api/inflate", R"({"pressure_mmhg": 5})", "text/plain")->status, 415);
  httplib::Headers elsewhere = {{"Host", "attacker.example:80"}};
  EXPECT_EQ(client_->Get("/api/status", elsewhere)->status, 403);
  const auto big = client_->Post("/api/inflate", std::string(serve::kMaxBodyBytes + 10, ' '), "application/json");
  ASSERT_TRUE(big);
  EXPECT_EQ(big->status, 413);
  EXPECT_EQ(status()["generation_latest"].get<uint64_t>(), gb) << "nothing refused started a solve";

  // Another preset is another lattice: roles and mesh again, from rest; a view asked for while it
  // solves is answered from the worker's checkpoints, on the new mesh's shapes.
  const int64_t preview_tets = status()["tetrahedra"];
  const auto c = client_->Post("/api/inflate", R"({"preset": "balanced"})", "application/json");
  ASSERT_EQ(c->status, 202);
  const uint64_t gc = nlohmann::json::parse(c->body)["generation"];
  const auto during = client_->Get(scope_query().c_str());
  EXPECT_EQ(during->status, 200) << during->body;
  ASSERT_TRUE(wait_solved(gc));
  const nlohmann::json sc = status();
  EXPECT_EQ(sc["preset"], "balanced");
  EXPECT_GT(sc["tetrahedra"].get<int64_t>(), preview_tets);
  EXPECT_TRUE(sc["converged"].get<bool>()) << sc.dump();
  EXPECT_NEAR(sc["pressure_mmhg"].get<double>(), 8.0, 1e-6);
}

// Rate limit and shutdown: at 5 requests a second, a burst of 20 meets 429 for most; a server asked to
// stop in the middle of a solve has stopped (listener returned, worker joined) within seconds.
TEST_F(ServeApi, RateLimitAndAPromptStopMidSolve) {
  ASSERT_NO_FATAL_FAILURE(start(5));
  int limited = 0;
  for (int k = 0; k < 20; ++k) limited += client_->Get("/api/status")->status == 429;
  EXPECT_GE(limited, 10);
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  ASSERT_EQ(client_->Post("/api/inflate", R"({"pressure_mmhg": 25})", "application/json")->status, 202);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto t0 = Clock::now();
  server_->stop();
  listener_.join();
  server_.reset();   // stops the worker: the solve is superseded at its next snapshot
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 20.0);
}


// A burst of 200 views at once, as many tabs or a script might ask: every one is answered, 200 or
// 503 (beyond the 6 views that may wait for the worker), within 10 s, and the status, polled
// meanwhile, answers every time within 1 s. cpp-httplib's listen backlog of 5 made the kernel drop
// most of such a burst's connections, which then waited a minute and more for their retries. The
// rate limit, tested on its own above, is raised here: it would answer part of the burst 429.
TEST_F(ServeApi, ABurstOfViewsIsAnsweredWhileTheStatusAnswers) {
  ASSERT_NO_FATAL_FAILURE(start(100000));
  ASSERT_EQ(client_->Get(scope_query().c_str())->status, 200) << "the case renders";
  constexpr int kBurst = 200;
  std::vector<int> codes(kBurst, -1);
  std::vector<double> answered_after(kBurst, -1.0);
  std::atomic<int> ready{0}, done{0};
  std::atomic<bool> go{false};
  std::vector<std::thread> burst;
  for (int k = 0; k < kBurst; ++k)
    burst.emplace_back([&, k] {
      httplib::Client c("127.0.0.1", port_);
      c.set_connection_timeout(15, 0);
      c.set_read_timeout(15, 0);
      ++ready;
      while (!go) std::this_thread::yield();
      const auto t0 = Clock::now();
      const auto r = c.Get(scope_query().c_str());
      answered_after[k] = seconds_since(t0);
      codes[k] = r ? r->status : -1;
      ++done;
    });
  while (ready < kBurst) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const auto t0 = Clock::now();
  go = true;
  double slowest_status = 0.0;
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  while (done < kBurst && seconds_since(t0) < 20.0) {
    const auto [code, seconds] = timed_status(port_);
    EXPECT_EQ(code, 200) << "the status after " << seconds_since(t0) << " s";
    EXPECT_LT(seconds, 1.0) << "the status after " << seconds_since(t0) << " s";
    slowest_status = std::max(slowest_status, seconds);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  for (std::thread& t : burst) t.join();
  int ok = 0, busy = 0;
  for (int k = 0; k < kBurst; ++k) {
    ok += codes[k] == 200;
    busy += codes[k] == 503;
    EXPECT_TRUE(codes[k] == 200 || codes[k] == 503) << "view " << k << ": " << codes[k];
    EXPECT_LT(answered_after[k], 10.0) << "view " << k;
  }
  EXPECT_GT(ok, 0);
  std::printf("%d views: %d answered 200, %d 503, the last after %.2f s; the slowest status %.3f s\n", kBurst, ok,
              busy, *std::max_element(answered_after.begin(), answered_after.end()), slowest_status);
}

// Slow clients: 13 connections, one more than the 12 request threads cpp-httplib's pool had, each
// sending its request's head one byte a second, as a stalled or hostile client does. Each is closed
// once its request has taken the read limit (5 s), and the status, polled meanwhile on connections
// of its own, answers every time within 1 s.
TEST_F(ServeApi, ClientsDrippingTheirRequestsAreDroppedWhileTheStatusAnswers) {
  ASSERT_NO_FATAL_FAILURE(start());
  const std::string head = "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: " + std::string(64, 'a') + "\r\n\r\n";
  constexpr int kSlow = 13;
  std::vector<int> slow;
  std::vector<Clock::time_point> connected;
  for (int k = 0; k < kSlow; ++k) {
    slow.push_back(connect_local(port_));
    connected.push_back(Clock::now());
  }
  ASSERT_EQ(std::count(slow.begin(), slow.end(), -1), 0);
  const auto t0 = Clock::now();
  std::vector<double> dropped_after(kSlow, -1.0);
  std::atomic<bool> dripping{true};
  std::thread drip([&] {
    for (std::size_t byte = 0; byte < head.size() && seconds_since(t0) < 12.0; ++byte) {
      for (int k = 0; k < kSlow; ++k) {
        if (dropped_after[k] >= 0) continue;
        if (closed_by_server(slow[k]) || ::send(slow[k], &head[byte], 1, MSG_NOSIGNAL) != 1)
          dropped_after[k] = seconds_since(connected[k]);
      }
      if (std::count(dropped_after.begin(), dropped_after.end(), -1.0) == 0) break;
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
    dripping = false;
  });
  double slowest_status = 0.0;
  int statuses = 0;
  while (dripping && seconds_since(t0) < 15.0) {
    const auto [code, seconds] = timed_status(port_);
    EXPECT_EQ(code, 200) << "the status after " << seconds_since(t0) << " s";
    EXPECT_LT(seconds, 1.0) << "the status after " << seconds_since(t0) << " s";
    slowest_status = std::max(slowest_status, seconds);
    ++statuses;
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  drip.join();
  for (int fd : slow) ::close(fd);
  for (int k = 0; k < kSlow; ++k) {
    if (dropped_after[k] < 0) {
      ADD_FAILURE() << "slow client " << k << " was never dropped";
      continue;
    }
    EXPECT_GE(dropped_after[k], 4.0) << "slow client " << k << " was dropped before its read limit";
    EXPECT_LT(dropped_after[k], 8.0) << "slow client " << k;
  }
  std::printf("%d statuses, the slowest %.3f s; slow clients dropped after %.1f to %.1f s\n", statuses,
              slowest_status, *std::min_element(dropped_after.begin(), dropped_after.end()),
              *std::max_element(dropped_after.begin(), dropped_after.end()));
}

// Nothing the user did not ask for runs: a key of a request's JSON that its endpoint does not read
// (a misspelling: "pressure_mmHg"), a key given twice, or bytes after the JSON value are refused
// with 400 naming the problem, on every endpoint that reads JSON, and nothing starts.
TEST_F(ServeApi, UnknownAndDuplicateKeysAndTrailingBytesAreRefused) {
  ASSERT_NO_FATAL_FAILURE(start());
  const uint64_t generation = status()["generation_latest"];
  const auto refused = [&](const std::string& path, const std::string& body, const std::string& says) {
    const auto r = body.empty() ? client_->Get(path.c_str()) : client_->Post(path.c_str(), body, "application/json");
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 400) << path << " " << body;
    EXPECT_NE(r->body.find(says), std::string::npos) << path << " " << body << " → " << r->body;
  };
  const std::string unknown = "is an unknown key", twice = "is given twice", trailing = "expected end of input";
  refused("/api/inflate", R"({"pressure_mmHg": 20})", R"(\"pressure_mmHg\" is an unknown key; did you mean \"pressure_mmhg\"?)");
  refused("/api/inflate", R"({"pressure_mmhg": 20, "pressure_mmhg": 8})", "pressure_mmhg " + twice);
  refused("/api/inflate", R"({"pressure_mmhg": 20} 8)", trailing);
  refused("/api/pick", R"({"x": 100, "y": 75, "sid": "left"})", R"(did you mean \"side\"?)");
  refused("/api/pick", R"({"x": 100, "y": 75, "x": 3})", "x " + twice);
  refused("/api/pick", R"({"x": 100, "y": 75}})", trailing);
  refused("/api/ports", R"({"target_label": 5, "grid": 20})", R"(did you mean \"grid_mm\"?)");
  refused("/api/ports", R"({"target_label": 5, "region": {"side": "anterior", "w": 200, "h": 150, "x0": 0, "y0": 0, "x1": 9, "y1": 9, "x2": 3}})",
          R"(region: \"x2\" is an unknown key)");
  refused("/api/ports", R"({"target_label": 5, "top": 3, "top": 4})", "top " + twice);
  refused("/api/ports", R"({"target_label": 5}{})", trailing);
  const std::string port = R"({"skin_point_mm": [0, 110, -20], "target_label": 5, "insertion_mm": 45})";
  refused("/api/plan", R"({"ports": [)" + port + R"(], "prots": []})", R"(\"prots\" is an unknown key; did you mean \"ports\"?)");
  refused("/api/plan", R"({"ports": [{"skin_point_mm": [0, 110, -20], "target_label": 5, "insertion": 45}]})", unknown);
  refused("/api/plan", R"({"ports": [], "ports": [)" + port + "]}", "ports " + twice);
  refused("/api/plan", R"({"ports": [)" + port + "]} x", trailing);
  const auto view = [](const std::string& json) {
    return "/api/scope.png?w=160&h=120&port=" + httplib::detail::encode_query_param(json);
  };
  refused(view(R"({"skin_point_mm": [0, 110, -20], "target_label": 5, "fov": 70})"), "", unknown);
  refused(view(R"({"skin_point_mm": [0, 110, -20], "target_label": 5, "target_label": 6})"), "", "target_label " + twice);
  refused(view(R"({"skin_point_mm": [0, 110, -20], "target_label": 5} ])"), "", trailing);
  const nlohmann::json s = status();
  EXPECT_EQ(s["generation_latest"].get<uint64_t>(), generation) << "nothing refused started a solve";
  EXPECT_EQ(s["plan"]["state"], "none") << "nothing refused started a plan";
}

// serve reads its scene with the CLI's reader: comments, as scenes written by hand hold (the
// fixture's scene starts with one), and a key given twice refused with the message `pneumo run` gives.
TEST(ServeScene, ReadAsTheCliReadsIt) {
  Progress::set_enabled(false);
  ScratchDir dir;
  const std::string commented = write_case(dir);
  ASSERT_EQ(testing_support::slurp(commented).rfind("//", 0), 0u);
  std::string text = testing_support::slurp(commented);
  text.insert(text.find('{') + 1, "\n  \"preset\": \"balanced\",");
  const std::string twice = dir.file("twice.json");
  std::ofstream(twice) << text;
  std::string cli_message;
  try {
    load_scene(twice);
  } catch (const InputError& e) {
    cli_message = e.what();
  }
  EXPECT_NE(cli_message.find("preset is given twice"), std::string::npos) << cli_message;
  serve::ServeOptions o;
  o.scene_path = twice;
  o.port = 0;
  try {
    serve::Server refused(o);
    ADD_FAILURE() << "a scene with a key given twice was served";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), cli_message);
  }
}
