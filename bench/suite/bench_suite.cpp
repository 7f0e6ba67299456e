#include "suite/bench_suite.h"

#include <omp.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <optional>
#include <string>

#include "common/cpu_load.h"
#include "common/memory.h"
#include "core/atomic_file.h"
#include "core/progress.h"
#include "render/gl_context.h"
#include "suite/bench_cases.h"
#include "suite/bench_context.h"
#include "suite/bench_report.h"
#include "suite/material_models.h"
#include "suite/speed_accuracy.h"
#include "suite/stability_map.h"
#include "suite/throughput.h"

namespace pneumo::bench {

namespace {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(colon + 2);
    }
  return "unknown";
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return b;
}

json machine_json(const BenchContext& ctx) {
  json m;
  m["cpu_model"] = cpu_model();
  m["logical_cpus"] = ::sysconf(_SC_NPROCESSORS_ONLN);
  m["openmp_threads"] = omp_get_max_threads();
  m["memory_gib"] = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGESIZE)) / double(1ull << 30);
  json cl = json::array();
  for (const Device& d : ctx.devices())
    if (d.opencl())
      cl.push_back({{"spec", d.info.spec()}, {"name", d.info.name}, {"platform", d.info.platform_name},
                    {"compute_units", d.info.compute_units}, {"version", d.info.version}});
  m["opencl_devices"] = cl;
  try {
    const GlContextInfo& gl = shared_gl_context().info();
    m["gl"] = {{"backend", gl_backend_name(gl.backend)}, {"renderer", gl.renderer}, {"version", gl.version}};
  } catch (const std::exception& e) {
    m["gl"] = {{"error", e.what()}};
  }
  return m;
}

/// One case's throughput with its peak memory (the high-water mark reset before the case was built).
/// `make` returns nullopt (and a note says why) for a case that cannot be built here.
void add_case(BenchContext& ctx, json& cases, const std::function<std::optional<BenchCase>()>& make,
              int pipeline_reps) {
  const bool reset = reset_peak_rss();
  const auto t0 = Clock::now();
  const std::optional<BenchCase> c = make();
  if (!c) return;
  json j = measure_case_throughput(ctx, *c, pipeline_reps);
  j["peak_rss_mib"] = peak_rss_mib();
  j["peak_rss_scope"] = reset ? "this case: building it and every measurement on it"
                              : "the process so far (the high-water mark could not be reset)";
  j["wall_s"] = seconds_since(t0);
  cases.push_back(j);
}

}  // namespace

json run_bench(const BenchOptions& opt) {
  const auto t0 = Clock::now();
  Progress::set_enabled(false);   // the solvers' and the warp's progress lines would drown the bench's own
  // Refuse unwritable targets before minutes of measuring.
  if (!opt.json_path.empty()) check_writable_target(opt.json_path);
  if (!opt.markdown_path.empty()) check_writable_target(opt.markdown_path);

  BenchContext ctx(opt.quick);
  json doc;
  doc["schema"] = "pneumo-bench/1";
  doc["pneumo_version"] = PNEUMO_VERSION;
  doc["date_utc"] = utc_now();
  doc["quick"] = opt.quick;
  doc["machine"] = machine_json(ctx);
  doc["machine"]["load_average_start"] = to_json(load_average());
  const CpuSample c0 = cpu_sample();

  // The bandwidth first, for every device, so a reader sees the machine before the stages.
  for (const Device& d : ctx.devices()) {
    try {
      ctx.bandwidth_gb_s(d);
    } catch (const std::exception& e) {
      ctx.note("triad on " + d.name + ": " + e.what());
    }
  }

  doc["stability"] = measure_stability_map(ctx);
  doc["speed_accuracy"] = measure_speed_accuracy(ctx);
  doc["material_models"] = measure_material_models(ctx, opt.real_ct_scene, opt.real_ct_fem_scene);

  json cases = json::array();
  // --quick meshes the small phantom with 16 mm cubes (9 k nodes, not its scene's 50 k): seconds, not minutes.
  add_case(ctx, cases, [&] { return phantom_case(PhantomSize::Small, opt.quick ? 4 : 0); }, opt.quick ? 1 : 3);
  if (opt.quick) {
    ctx.note("--quick: the small phantom only; medium, large and the real CT are measured by the full run");
  } else {
    add_case(ctx, cases, [] { return phantom_case(PhantomSize::Medium); }, 3);
    add_case(ctx, cases, [] { return phantom_case(PhantomSize::Large); }, 1);
    add_case(ctx, cases, [&] {
      std::string why;
      std::optional<BenchCase> c = scene_case(opt.real_ct_scene, "real_ct", why);
      if (!c) ctx.note("real CT skipped: " + why);
      return c;
    }, 3);
  }
  doc["throughput"] = cases;
  doc["bandwidth"] = ctx.bandwidth_json();
  doc["machine"]["load_average_end"] = to_json(load_average());
  doc["other_cores_mean"] = other_cores(c0, cpu_sample());
  doc["notes"] = ctx.notes();
  doc["wall_time_s"] = seconds_since(t0);

  if (!opt.json_path.empty()) write_text_file_atomic(opt.json_path, doc.dump(2) + "\n");
  if (!opt.markdown_path.empty()) write_bench_markdown(doc, opt.markdown_path);
  return doc;
}

}  // namespace pneumo::bench
