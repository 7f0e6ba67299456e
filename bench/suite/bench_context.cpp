#include "suite/bench_context.h"

#include <omp.h>

#include <chrono>
#include <cstdio>

#include "perf/bandwidth.h"

namespace pneumo::bench {

namespace {
// Triad arrays far beyond the 32 MiB L3 (as bench_foundation); smaller in the smoke run, where only the
// harness is checked (the ratio is then not a DRAM figure, and the notes say so).
constexpr std::size_t kTriadBytes = 512ull << 20, kQuickTriadBytes = 64ull << 20;
constexpr int kTriadReps = 5, kQuickTriadReps = 2;
}  // namespace

std::string Device::description() const {
  if (opencl()) return info.name + " (" + info.spec() + "), float32";
  return "CPU reference, double, " + std::to_string(threads) + (threads == 1 ? " thread" : " threads");
}

BenchContext::BenchContext(bool quick) : quick_(quick) {
  const int all = omp_get_max_threads();
  devices_.push_back(Device{"cpu_1thread", 1, {}});
  if (all > 1) devices_.push_back(Device{"cpu_" + std::to_string(all) + "threads", all, {}});
  try {
    for (const ocl::DeviceInfo& info : ocl::list_devices()) devices_.push_back(Device{info.spec(), 0, info});
  } catch (const std::exception& e) {
    note(std::string("OpenCL: ") + e.what());
  }
  if (devices_.size() == std::size_t(all > 1 ? 2 : 1)) note("no OpenCL device: " + ocl::no_device_hint());
  if (quick_)
    note("--quick: triad arrays of 64 MiB (partly cache-resident), so roofline ratios of this run are not DRAM "
         "figures; the smoke run checks the harness, not the machine");
}

double BenchContext::bandwidth_gb_s(const Device& d) {
  auto it = bandwidth_cache_.find(d.name);
  if (it != bandwidth_cache_.end()) return it->second;
  const std::size_t bytes = quick_ ? kQuickTriadBytes : kTriadBytes;
  const int reps = quick_ ? kQuickTriadReps : kTriadReps;
  perf::Bandwidth bw;
  if (d.opencl()) bw = perf::measure_triad_opencl(cl(d), bytes, reps);
  else with_threads(d.threads, [&] { bw = perf::measure_triad_native(bytes, reps); });
  bandwidth_[d.name] = {{"median_gb_s", bw.median_gb_s}, {"min_gb_s", bw.min_gb_s}, {"max_gb_s", bw.max_gb_s},
                        {"repetitions", bw.repetitions}, {"bytes_per_array", bw.bytes_per_array},
                        {"device", d.description()}};
  std::fprintf(stderr, "[bench] triad on %s: %.1f GB/s\n", d.name.c_str(), bw.median_gb_s);
  return bandwidth_cache_[d.name] = bw.median_gb_s;
}

ocl::Context& BenchContext::cl(const Device& d) {
  auto& ctx = contexts_[d.name];
  if (!ctx) ctx = ocl::Context::shared(ocl::parse_device_spec(d.info.spec()));
  return *ctx;
}

void BenchContext::note(const std::string& text) {
  std::fprintf(stderr, "[bench] note: %s\n", text.c_str());
  notes_.push_back(text);
}

void with_threads(int threads, const std::function<void()>& fn) {
  const int before = omp_get_max_threads();
  if (threads > 0) omp_set_num_threads(threads);
  try {
    fn();
  } catch (...) {
    omp_set_num_threads(before);
    throw;
  }
  omp_set_num_threads(before);
}

Summary time_reps(int reps, int warmups, const std::function<void()>& fn) {
  for (int w = 0; w < warmups; ++w) fn();
  std::vector<double> s;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    s.push_back(seconds_since(t0));
  }
  return summarize(s);
}

}  // namespace pneumo::bench
