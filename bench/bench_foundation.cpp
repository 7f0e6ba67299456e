// Foundation benchmarks: the machine's memory bandwidth (STREAM triad, natively and on every
// OpenCL device: the denominator of every roofline ratio), volume I/O and phantom generation
// throughput. Run: build/bench/pneumo_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Medians over repetitions are what to compare; never a pass/fail on time.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <unistd.h>

#include "cl/cl_runtime.h"
#include "io/volume_io.h"
#include "perf/bandwidth.h"
#include "phantom/phantom.h"
#include "core/progress.h"

using namespace pneumo;

namespace {

constexpr std::size_t kTriadBytes = 512ull << 20;   // per array: far beyond the 32 MiB L3

void BM_TriadNative(benchmark::State& state) {
  for (auto _ : state) {
    const auto bw = perf::measure_triad_native(kTriadBytes, 1);
    state.SetIterationTime(3.0 * kTriadBytes / (bw.median_gb_s * 1e9));
    state.counters["GB_per_s"] = bw.median_gb_s;
  }
  state.SetBytesProcessed(int64_t(state.iterations()) * 3 * kTriadBytes);
}
BENCHMARK(BM_TriadNative)->UseManualTime()->Unit(benchmark::kMillisecond);

void BM_TriadOpenCL(benchmark::State& state) {
  const auto devices = ocl::list_devices();
  if (state.range(0) >= int64_t(devices.size())) {
    state.SkipWithError("no such OpenCL device");
    return;
  }
  auto ctx = ocl::Context::shared(ocl::parse_device_spec(devices[state.range(0)].spec()));
  state.SetLabel(ctx->info().name);
  for (auto _ : state) {
    const auto bw = perf::measure_triad_opencl(*ctx, kTriadBytes, 1);
    state.SetIterationTime(3.0 * kTriadBytes / (bw.median_gb_s * 1e9));
    state.counters["GB_per_s"] = bw.median_gb_s;
  }
  state.SetBytesProcessed(int64_t(state.iterations()) * 3 * kTriadBytes);
}
BENCHMARK(BM_TriadOpenCL)->Arg(0)->UseManualTime()->Unit(benchmark::kMillisecond);

void BM_PhantomSmall(benchmark::State& state) {
  Progress::set_enabled(false);
  for (auto _ : state) benchmark::DoNotOptimize(make_phantom(PhantomSize::Small));
  state.counters["voxels_per_s"] = benchmark::Counter(
      double(state.iterations()) * phantom_geometry(PhantomSize::Small).voxel_count(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PhantomSmall)->Unit(benchmark::kMillisecond);

void BM_NiftiGzWriteRead(benchmark::State& state) {
  Progress::set_enabled(false);
  const Phantom p = make_phantom(PhantomSize::Small);
  const auto dir = std::filesystem::temp_directory_path() / ("pneumo_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "ct.nii.gz").string();
  for (auto _ : state) {
    write_volume(p.ct, path);
    benchmark::DoNotOptimize(read_volume(path));
  }
  state.counters["voxels_per_s"] =
      benchmark::Counter(double(state.iterations()) * p.ct.voxel_count(), benchmark::Counter::kIsRate);
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_NiftiGzWriteRead)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
