// Image-warp throughput (method.md §7): output voxels per second for the large phantom (512×512×400 at
// 0.75 mm, 105 M voxels), the CPU warp (double, 1 thread and all threads) against every OpenCL device
// (float32), each next to the STREAM-triad bandwidth measured in this process.
//
//   POCL_CACHE_DIR=/tmp/pocl build/bench/pneumo_bench --benchmark_filter=Warp
//       --benchmark_repetitions=3 --benchmark_report_aggregates_only=true   (one command line)
//
// The deformation is the phantom's own, solved in-process at its scene's 12 mmHg with the static
// solver (the CPU reference, as `pneumo simulate` runs it): the mesh, the roles and the volumes are
// exactly what `pneumo warp` gets. Setting it up takes about a minute (phantom, solve) and is not timed.
//
// Names: BM_Warp/<device>/large, device = cpu_1thread, cpu_<N>threads, opencl_<platform>_<device>.
// One iteration is one whole warp as the pipeline calls it: warp_cpu, or warp_opencl including the
// tetrahedra's preparation, uploads of the source volumes and downloads of the results (on PoCL those
// are memory copies the pipeline pays too). Kernels are built before timing.
//
// Counters (compare medians; never a pass/fail on time):
//   voxels_per_s        output voxels per second
//   bytes_per_voxel     DRAM bytes per output voxel counted from the data (below)
//   bandwidth_gb_s      STREAM triad in this process, same device and threads (1 GB = 1e9 bytes)
//   roofline_fraction   voxels_per_s / (bandwidth / bytes_per_voxel)
//   other_cores         CPU (in cores) other processes used meanwhile; above ~0.1 the run was contended
//   x_vtk, x_itk        voxels_per_s over the peers measured on the reference machine (common/warp_cost.h):
//                       VTK vtkProbeFilter pull-back 1.04 Mvoxel/s, ITK dense-field resampling 29.5 Mvoxel/s
//
// Bytes per output voxel: common/warp_cost.h (shared with `pneumo bench`).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

#include "cl/cl_runtime.h"
#include "common/cpu_load.h"
#include "common/warp_cost.h"
#include "core/log.h"
#include "core/progress.h"
#include "perf/bandwidth.h"
#include "phantom/phantom.h"
#include "pipeline/scene_stages.h"
#include "roles/roles.h"
#include "scene/scene.h"
#include "solve/solve_on_device.h"
#include "solve/solver.h"
#include "warp/warp.h"

using namespace pneumo;

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::size_t kTriadBytes = 512ull << 20;
constexpr int kTriadReps = 5;
using bench::CpuSample;
using bench::cpu_sample;
using bench::other_cores;
constexpr double kVtkVoxelsPerS = bench::kVtkWarpVoxelsPerS;
constexpr double kItkVoxelsPerS = bench::kItkWarpVoxelsPerS;
constexpr double kCpuBytesPerVoxel = bench::kWarpCpuBytesPerVoxel;
constexpr double kClBytesPerVoxel = bench::kWarpClBytesPerVoxel;

struct WarpCase {
  RoleVolume roles;
  WarpMesh mesh;
  WarpBox box;
  WarpSource source() const { return WarpSource{roles.ct.data<float>(), roles.label.data(), roles.role.data()}; }
};

const WarpCase& warp_case() {
  static std::mutex mutex;
  static std::unique_ptr<WarpCase> c;
  std::lock_guard<std::mutex> lock(mutex);
  if (c) return *c;
  Progress::set_enabled(false);
  const log::Level level = log::level();
  log::set_level(log::Level::Quiet);
  const auto t0 = Clock::now();
  c = std::make_unique<WarpCase>();
  const PhantomSize size = PhantomSize::Large;
  const Scene scene = parse_scene(nlohmann::json::parse(phantom_scene_json(size)), "");
  const Phantom ph = make_phantom(size);
  c->roles = assign_roles(scene, ph.ct, &ph.labels);
  const Mesh mesh = build_scene_mesh(voxel_roles_of(c->roles), scene);
  const SolveResult r = solve_on_device(nullptr, mesh, solve_options_from_scene(scene));
  log::set_level(level);
  std::vector<Vec3> u(r.x.size());
  for (std::size_t n = 0; n < u.size(); ++n) u[n] = r.x[n] - mesh.rest_m[n];
  c->mesh = make_warp_mesh(mesh, u);
  c->box = WarpBox{c->roles.pad.lo, ph.ct.geometry().dims};
  std::fprintf(stderr, "[bench_warp] large phantom: %lldx%lldx%lld output voxels, %lld tetrahedra, solved (%s) in "
                       "%lld steps; set up in %.0f s\n",
               (long long)c->box.dims[0], (long long)c->box.dims[1], (long long)c->box.dims[2],
               (long long)c->mesh.tet_count(), stop_reason_text(r.stop_reason), (long long)r.steps,
               std::chrono::duration<double>(Clock::now() - t0).count());
  return *c;
}

WarpOptions options() { return WarpOptions{}; }

void report(benchmark::State& state, double seconds, int64_t voxels, double bytes_per_voxel, double bandwidth_gb_s,
            const CpuSample& c0, const std::string& label) {
  const double rate = double(state.iterations()) * double(voxels) / seconds;
  state.counters["voxels_per_s"] = rate;
  state.counters["bytes_per_voxel"] = bytes_per_voxel;
  state.counters["bandwidth_gb_s"] = bandwidth_gb_s;
  state.counters["roofline_fraction"] = rate / (bandwidth_gb_s * 1e9 / bytes_per_voxel);
  state.counters["other_cores"] = other_cores(c0, cpu_sample());
  state.counters["x_vtk"] = rate / kVtkVoxelsPerS;
  state.counters["x_itk"] = rate / kItkVoxelsPerS;
  state.SetLabel(label);
}

void BM_WarpCpu(benchmark::State& state, int threads) {
  const WarpCase& c = warp_case();
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
  const double bw = perf::measure_triad_native(kTriadBytes, kTriadReps).median_gb_s;
  const CpuSample c0 = cpu_sample();
  const auto t0 = Clock::now();
  int64_t gas = 0;
  for (auto _ : state) {   // one warp a repetition, on fresh memory, as `pneumo warp` runs
    const WarpResult r = warp_on_device(nullptr, c.mesh, c.source(), c.box, options());
    gas = r.gas_voxels;
    benchmark::DoNotOptimize(r.ct_hu.data());
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  omp_set_num_threads(before);
  state.counters["gas_voxels"] = double(gas);
  report(state, seconds, c.box.voxel_count(), kCpuBytesPerVoxel, bw, c0,
         "CPU warp, double, " + std::to_string(threads) + " thread(s)");
}

void BM_WarpCl(benchmark::State& state, ocl::DeviceInfo info) {
  const WarpCase& c = warp_case();
  auto ctx = ocl::Context::shared(ocl::parse_device_spec(info.spec()));
  const double bw = perf::measure_triad_opencl(*ctx, kTriadBytes, kTriadReps).median_gb_s;
  warp_on_device(ctx.get(), c.mesh, c.source(), c.box, options());   // builds the program, compiles both kernels
  const CpuSample c0 = cpu_sample();
  const auto t0 = Clock::now();
  int64_t gas = 0;
  for (auto _ : state) {
    const WarpResult r = warp_on_device(ctx.get(), c.mesh, c.source(), c.box, options());
    gas = r.gas_voxels;
    benchmark::DoNotOptimize(r.ct_hu.data());
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  state.counters["gas_voxels"] = double(gas);
  report(state, seconds, c.box.voxel_count(), kClBytesPerVoxel, bw, c0, info.spec() + " " + info.name + ", float32");
}

bool register_all() {
  const int all_threads = omp_get_max_threads();
  const auto finish = [](benchmark::internal::Benchmark* b) {
    b->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(1);
  };
  finish(benchmark::RegisterBenchmark("BM_Warp/cpu_1thread/large", BM_WarpCpu, 1));
  if (all_threads > 1)
    finish(benchmark::RegisterBenchmark(("BM_Warp/cpu_" + std::to_string(all_threads) + "threads/large").c_str(),
                                        BM_WarpCpu, all_threads));
  std::vector<ocl::DeviceInfo> devices;
  try {
    devices = ocl::list_devices();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "[bench_warp] OpenCL: %s\n", e.what());
  }
  for (const auto& d : devices)
    finish(benchmark::RegisterBenchmark(
        ("BM_Warp/opencl_" + std::to_string(d.platform_index) + "_" + std::to_string(d.device_index) + "/large").c_str(),
        BM_WarpCl, d));
  return true;
}

[[maybe_unused]] const bool registered = register_all();

}  // namespace
