// Solver throughput benchmarks: force evaluations per second and node-updates per second (one node advanced by one
// explicit step, its force evaluation included) on the small, medium and large phantom meshes, for the CPU
// reference (double, 1 thread and all threads) and every OpenCL device (float32), each with a roofline ratio.
//
//   POCL_CACHE_DIR=/tmp/pocl build/bench/pneumo_bench --benchmark_filter='Forces|ExplicitStep'
//       --benchmark_repetitions=5 --benchmark_report_aggregates_only=true   (one command line)
//
// Names: BM_Forces/<device>/<size> and BM_ExplicitStep/<device>/<size>, device = cpu_1thread, cpu_<N>threads
// (N = all threads OpenMP would use), opencl_<platform>_<device>.
//
// Counters (medians over repetitions are what to compare; never a pass/fail on time):
//   force_evals_per_s      whole-mesh force evaluations per second
//   node_updates_per_s     BM_ExplicitStep: nodes × steps per second; BM_Forces: nodes × evaluations per second
//   bytes_per_node_update  the DRAM bytes one node's update must move, counted from the data structures (below);
//                          for BM_Forces the force evaluation's share only
//   flops_per_node_update  the floating-point operations of the same
//   bandwidth_gb_s         STREAM triad measured in this process on the same device with the same threads
//                          (perf::measure_triad_native / measure_triad_opencl), 1 GB = 1e9 bytes
//   roofline_fraction      achieved rate / min(bandwidth / bytes, peak / flops): the bound that binds. The label
//                          says which ("memory-bound" or "compute-bound").
//   other_cores            CPU (in cores) that other processes used while it ran: the machine is shared, and a run
//                          with other_cores above ~0.1 is contended (discard it)
//   nodes, springs         the mesh
//   spring_records_per_node  OpenCL: spring records the gather reads per node, padding included (blocks of 8
//                          nodes of equal degree, see kernels/msd_forces.cl)
//   working_set_mib        bytes_per_node_update × nodes: below the L3 (32 MiB here) the data can stay in cache
//                          between passes, and the DRAM-triad roofline is then a conservative bound (a fraction
//                          above 1 is possible)
//
// Peak FLOP rates and the byte and FLOP counts per node-update: common/solver_cost.h (shared with `pneumo bench`).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <cstring>
#include <string>
#include <vector>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cl/cl_runtime.h"
#include "core/stopwatch.h"
#include "common/cpu_load.h"
#include "common/explicit_update.h"
#include "common/solver_cost.h"
#include "core/log.h"
#include "core/progress.h"
#include "mesh/adjacency.h"
#include "mesh/mesh.h"
#include "perf/bandwidth.h"
#include "phantom/phantom.h"
#include "pipeline/scene_stages.h"
#include "roles/roles.h"
#include "scene/scene.h"
#include "solve/forces.h"
#include "solve/forces_cl.h"
#include "solve/solver.h"
#include "solve/solver_cl.h"

using namespace pneumo;
using pneumo::bench::Cost;
using pneumo::bench::CpuSample;
using pneumo::bench::cpu_sample;
using pneumo::bench::cl_peak_flop_s;
using pneumo::bench::kPeakF32PerCore;

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kStepsPerIteration = 10;                // explicit steps per timed iteration
constexpr std::size_t kTriadBytes = 512ull << 20;     // per array, far beyond the 32 MiB L3 (as bench_foundation)
constexpr int kTriadReps = 5;
/// The meshes: the three phantoms as their scenes mesh them (8–9 mm cubes: working sets of 14–34 MiB, about the
/// 32 MiB L3), and the large phantom at 3 mm cubes (cube_voxels 4: ~0.9 M nodes, a working set of ~300 MiB), where
/// the data cannot stay in cache and the DRAM roofline is the honest bound.
struct Case {
  PhantomSize phantom;
  int cube_voxels;   // 0: the scene's
  const char* name;
  bool operator<(const Case& o) const { return std::string(name) < o.name; }
};
const Case kSizes[] = {{PhantomSize::Small, 0, "small"},
                       {PhantomSize::Medium, 0, "medium"},
                       {PhantomSize::Large, 0, "large"},
                       {PhantomSize::Large, 4, "large_3mm"}};

// ---- the meshes, built once per size as the pipeline builds them -------------------------------

struct MeshCase {
  Mesh mesh;
  ForceModel model;      // the scene's: 12 mmHg on the cavity faces, volume term off
  double dt_s = 0.0;     // dt_safety × the stability bound, as the explicit solver chooses it
  std::vector<Vec3> x0, v0;   // a perturbed state: nothing trivially zero
};

const MeshCase& mesh_case(const Case& size) {
  static std::mutex mutex;
  static std::map<Case, std::unique_ptr<MeshCase>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[size];
  if (slot) return *slot;
  Progress::set_enabled(false);
  const log::Level log_level = log::level();
  log::set_level(log::Level::Quiet);   // the phantom's scene names a few labels its CT lacks: a warning per size
  const auto t0 = Clock::now();
  auto c = std::make_unique<MeshCase>();
  Scene scene = parse_scene(nlohmann::json::parse(phantom_scene_json(size.phantom)), "");
  if (size.cube_voxels > 0) scene.mesh.cube_voxels = size.cube_voxels;
  {
    const Phantom ph = make_phantom(size.phantom);
    const RoleVolume rv = assign_roles(scene, ph.ct, &ph.labels);
    c->mesh = build_scene_mesh(voxel_roles_of(rv), scene);
  }
  log::set_level(log_level);
  const SolveOptions opt = solve_options_from_scene(scene);
  c->model = opt.forces;
  c->model.volume_stiffness_pa = 0.0;   // the static solver's default; the explicit scheme's too
  c->dt_s = opt.dt_s > 0 ? opt.dt_s : opt.dt_safety * stable_time_step(c->mesh, c->model.damping);
  const int64_t N = c->mesh.node_count();
  c->x0 = c->mesh.rest_m;
  c->v0.assign(N, Vec3::Zero());
  for (int64_t n = 0; n < N; ++n) {   // deterministic: ~0.1 mm and ~1 mm/s
    const double a = std::sin(0.37 * double(n)), b = std::cos(0.61 * double(n)), s = std::sin(0.13 * double(n));
    c->x0[n] += 1e-4 * Vec3(a, b, s);
    c->v0[n] = 1e-3 * Vec3(b, s, a);
  }
  const MeshStats& st = c->mesh.stats;
  std::fprintf(stderr, "[bench_solver] %s mesh: %lld nodes, %lld springs, %lld tetrahedra, %lld pressure tetrahedra, "
                       "dt %.3g ms, pressure %.1f Pa (built in %.1f s)\n",
               size.name, (long long)st.nodes, (long long)st.springs, (long long)st.tetrahedra,
               (long long)st.pressure_tetrahedra, c->dt_s * 1e3, c->model.pressure_pa,
               std::chrono::duration<double>(Clock::now() - t0).count());
  slot = std::move(c);
  return *slot;
}

// ---- the bandwidth, measured once per device (and thread count) in this process -------------------

double native_bandwidth_gb_s(int threads) {
  static std::mutex mutex;
  static std::map<int, double> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = cache.find(threads);
  if (it != cache.end()) return it->second;
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
  const double gb_s = perf::measure_triad_native(kTriadBytes, kTriadReps).median_gb_s;
  omp_set_num_threads(before);
  std::fprintf(stderr, "[bench_solver] triad, native, %d thread(s): %.1f GB/s\n", threads, gb_s);
  return cache[threads] = gb_s;
}

// An OpenCL device held for the whole process (Context::shared only caches weakly).
struct ClDevice {
  std::shared_ptr<ocl::Context> ctx;
  double bandwidth_gb_s = 0.0;
};

ClDevice& cl_device(const ocl::DeviceInfo& info) {
  static std::mutex mutex;
  static std::map<std::string, ClDevice> cache;
  std::lock_guard<std::mutex> lock(mutex);
  ClDevice& d = cache[info.spec()];
  if (!d.ctx) {
    d.ctx = ocl::Context::shared(ocl::parse_device_spec(info.spec()));
    d.bandwidth_gb_s = perf::measure_triad_opencl(*d.ctx, kTriadBytes, kTriadReps).median_gb_s;
    std::fprintf(stderr, "[bench_solver] triad, %s (%s): %.1f GB/s\n", info.spec().c_str(), info.name.c_str(),
                 d.bandwidth_gb_s);
  }
  return d;
}



/// Sets the roofline counters from the achieved node rate (node-updates or node force evaluations per second).
void report_roofline(benchmark::State& state, const Mesh& m, const Cost& cost, double node_rate,
                     double bandwidth_gb_s, double peak_flop_s, const std::string& device_label) {
  const pneumo::bench::Roofline r = pneumo::bench::roofline(node_rate, cost, bandwidth_gb_s, peak_flop_s);
  state.counters["bytes_per_node_update"] = cost.bytes;
  state.counters["flops_per_node_update"] = cost.flops;
  state.counters["bandwidth_gb_s"] = bandwidth_gb_s;
  state.counters["roofline_fraction"] = r.fraction;
  state.counters["working_set_mib"] = cost.bytes * double(m.node_count()) / double(1 << 20);
  state.SetLabel(device_label + (r.memory_bound ? ", memory-bound" : ", compute-bound"));
}

void mesh_counters(benchmark::State& state, const Mesh& m) {
  state.counters["nodes"] = double(m.node_count());
  state.counters["springs"] = double(m.springs.size());
}

// ---- contention: CPU used by other processes while a benchmark ran (Linux /proc; −1 elsewhere) ----

/// Cores' worth of CPU that other processes used between a and b (e.g. 0.9: another job held a core).
void report_other_cores(benchmark::State& state, const CpuSample& a, const CpuSample& b) {
  state.counters["other_cores"] = pneumo::bench::other_cores(a, b);
}

/// Runs `fn` with OpenMP limited to `threads`, restoring the previous limit after.
template <class F>
void with_threads(int threads, F&& fn) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
  fn();
  omp_set_num_threads(before);
}

// ---- CPU reference ------------------------------------------------------------------------------

void BM_ForcesCpu(benchmark::State& state, const Case& size, int threads) {
  const MeshCase& mc = mesh_case(size);
  const double bw = native_bandwidth_gb_s(threads);
  const Mesh& m = mc.mesh;
  ForceEvaluator eval(m);
  std::vector<Vec3> f;
  double seconds = 0.0;
  with_threads(threads, [&] {
    eval.evaluate(mc.model, mc.x0, mc.v0, f);   // allocates the per-element scratch
    const CpuSample c0 = cpu_sample();
    const auto t0 = Clock::now();
    for (auto _ : state) {
      eval.evaluate(mc.model, mc.x0, mc.v0, f);
      benchmark::DoNotOptimize(f.data());
      benchmark::ClobberMemory();
    }
    seconds = seconds_since(t0);
    report_other_cores(state, c0, cpu_sample());
  });
  const double evals = double(state.iterations()), N = double(m.node_count());
  state.counters["force_evals_per_s"] = benchmark::Counter(evals, benchmark::Counter::kIsRate);
  state.counters["node_updates_per_s"] = benchmark::Counter(evals * N, benchmark::Counter::kIsRate);
  mesh_counters(state, m);
  report_roofline(state, m, pneumo::bench::cpu_force_cost(m, mc.model), evals * N / seconds, bw, pneumo::bench::cpu_peak_flop_s(threads),
                  "CPU reference, double, " + std::to_string(threads) + " thread(s)");
}

void BM_ExplicitStepCpu(benchmark::State& state, const Case& size, int threads) {
  const MeshCase& mc = mesh_case(size);
  const double bw = native_bandwidth_gb_s(threads);
  const Mesh& m = mc.mesh;
  const int64_t N = m.node_count();
  ForceEvaluator eval(m);
  std::vector<Vec3> x = mc.x0, v = mc.v0, f;
  const double dt = mc.dt_s;
  const auto step = [&] {
    eval.evaluate(mc.model, x, v, f);
    bench::explicit_update(m, dt, f, x, v);
  };
  double seconds = 0.0;
  with_threads(threads, [&] {
    step();
    const CpuSample c0 = cpu_sample();
    const auto t0 = Clock::now();
    for (auto _ : state) {
      for (int s = 0; s < kStepsPerIteration; ++s) step();
      benchmark::DoNotOptimize(x.data());
      benchmark::ClobberMemory();
    }
    seconds = seconds_since(t0);
    report_other_cores(state, c0, cpu_sample());
  });
  for (int64_t n = 0; n < N; ++n)
    if (!x[n].allFinite()) {
      state.SkipWithError("the explicit steps diverged (non-finite positions)");
      return;
    }
  const double steps = double(state.iterations()) * kStepsPerIteration;
  state.counters["force_evals_per_s"] = benchmark::Counter(steps, benchmark::Counter::kIsRate);
  state.counters["node_updates_per_s"] = benchmark::Counter(steps * double(N), benchmark::Counter::kIsRate);
  mesh_counters(state, m);
  const Cost cost = pneumo::bench::cpu_step_cost(m, mc.model);
  report_roofline(state, m, cost, steps * double(N) / seconds, bw, pneumo::bench::cpu_peak_flop_s(threads),
                  "CPU reference, double, " + std::to_string(threads) + " thread(s)");
}

// ---- OpenCL -------------------------------------------------------------------------------------

/// The device's force evaluator for a size, uploaded once.
ClForceEvaluator& cl_forces(ClDevice& dev, const ocl::DeviceInfo& info, const Case& size) {
  static std::mutex mutex;
  static std::map<std::pair<std::string, Case>, std::unique_ptr<ClForceEvaluator>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{info.spec(), size}];
  if (!slot) {
    const MeshCase& mc = mesh_case(size);
    slot = std::make_unique<ClForceEvaluator>(*dev.ctx, mc.mesh);
    slot->upload_state(mc.x0, mc.v0);
  }
  return *slot;
}

void BM_ForcesCl(benchmark::State& state, Case size, ocl::DeviceInfo info) {
  try {
    const MeshCase& mc = mesh_case(size);
    ClDevice& dev = cl_device(info);
    ClForceEvaluator& eval = cl_forces(dev, info, size);
    auto& q = dev.ctx->queue();
    for (int w = 0; w < 2; ++w) eval.evaluate(mc.model);   // the first launch of each kernel compiles on PoCL
    q.finish();
    const CpuSample c0 = cpu_sample();
    const auto t0 = Clock::now();
    for (auto _ : state) {
      eval.evaluate(mc.model);
      q.finish();
    }
    const double seconds = seconds_since(t0);
    report_other_cores(state, c0, cpu_sample());
    const double evals = double(state.iterations()), N = double(mc.mesh.node_count());
    state.counters["force_evals_per_s"] = benchmark::Counter(evals, benchmark::Counter::kIsRate);
    state.counters["node_updates_per_s"] = benchmark::Counter(evals * N, benchmark::Counter::kIsRate);
    state.counters["spring_records_per_node"] = eval.spring_records_per_node();
    mesh_counters(state, mc.mesh);
    report_roofline(state, mc.mesh, pneumo::bench::cl_force_cost(mc.mesh, mc.model, eval.spring_records_per_node(), 1.0), evals * N / seconds,
                    dev.bandwidth_gb_s, cl_peak_flop_s(info), info.name + ", float32");
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

void BM_ExplicitStepCl(benchmark::State& state, Case size, ocl::DeviceInfo info) {
  try {
    const MeshCase& mc = mesh_case(size);
    ClDevice& dev = cl_device(info);
    // The stepper keeps its state on the device across calls of this function (the dynamics stay bounded: damped,
    // dt at half the stability limit).
    static std::mutex mutex;
    static std::map<std::pair<std::string, Case>, std::unique_ptr<ClExplicitStepper>> cache;
    ClExplicitStepper* stepper;
    {
      std::lock_guard<std::mutex> lock(mutex);
      auto& slot = cache[{info.spec(), size}];
      if (!slot) slot = std::make_unique<ClExplicitStepper>(*dev.ctx, mc.mesh, mc.model, mc.dt_s);
      stepper = slot.get();
    }
    // The same tables the stepper builds; its steps gather the blocks with a free node only.
    const ClForceEvaluator& tables = cl_forces(dev, info, size);
    const auto free = ClForceEvaluator::Nodes::Free;
    const double spring_records = tables.spring_records_per_node(free), gathered = tables.gathered_fraction(free);
    stepper->steps(2);   // warm every kernel (PoCL compiles at the first launch)
    stepper->finish();
    const CpuSample c0 = cpu_sample();
    const auto t0 = Clock::now();
    for (auto _ : state) {
      stepper->steps(kStepsPerIteration);
      stepper->finish();
    }
    const double seconds = seconds_since(t0);
    report_other_cores(state, c0, cpu_sample());
    const double steps = double(state.iterations()) * kStepsPerIteration, N = double(mc.mesh.node_count());
    state.counters["force_evals_per_s"] = benchmark::Counter(steps, benchmark::Counter::kIsRate);
    state.counters["node_updates_per_s"] = benchmark::Counter(steps * N, benchmark::Counter::kIsRate);
    state.counters["spring_records_per_node"] = spring_records;
    state.counters["gathered_fraction"] = gathered;
    mesh_counters(state, mc.mesh);
    const Cost cost = pneumo::bench::cl_step_cost(mc.mesh, mc.model, spring_records, gathered);
    report_roofline(state, mc.mesh, cost, steps * N / seconds, dev.bandwidth_gb_s, cl_peak_flop_s(info),
                    info.name + ", float32");
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

// ---- registration -------------------------------------------------------------------------------

bool register_all() {
  const int all_threads = omp_get_max_threads();
  std::vector<std::pair<std::string, int>> cpu = {{"cpu_1thread", 1}};
  if (all_threads > 1) cpu.push_back({"cpu_" + std::to_string(all_threads) + "threads", all_threads});
  std::vector<ocl::DeviceInfo> devices;
  try {
    devices = ocl::list_devices();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "[bench_solver] OpenCL: %s\n", e.what());
  }
  if (devices.empty()) std::fprintf(stderr, "[bench_solver] %s\n", ocl::no_device_hint().c_str());
  const auto cl_name = [](const ocl::DeviceInfo& d) {
    return "opencl_" + std::to_string(d.platform_index) + "_" + std::to_string(d.device_index);
  };
  const auto finish = [](benchmark::internal::Benchmark* b) { b->UseRealTime()->Unit(benchmark::kMillisecond); };
  for (const Case& size : kSizes) {
    const std::string sz = size.name;
    for (const auto& [name, threads] : cpu)
      finish(benchmark::RegisterBenchmark(("BM_Forces/" + name + "/" + sz).c_str(), BM_ForcesCpu, size, threads));
    for (const auto& d : devices)
      finish(benchmark::RegisterBenchmark(("BM_Forces/" + cl_name(d) + "/" + sz).c_str(), BM_ForcesCl, size, d));
  }
  for (const Case& size : kSizes) {
    const std::string sz = size.name;
    for (const auto& [name, threads] : cpu)
      finish(benchmark::RegisterBenchmark(("BM_ExplicitStep/" + name + "/" + sz).c_str(), BM_ExplicitStepCpu, size,
                                          threads));
    for (const auto& d : devices)
      finish(benchmark::RegisterBenchmark(("BM_ExplicitStep/" + cl_name(d) + "/" + sz).c_str(), BM_ExplicitStepCl,
                                          size, d));
  }
  return true;
}

[[maybe_unused]] const bool registered = register_all();

}  // namespace
