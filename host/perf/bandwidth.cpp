#include "perf/bandwidth.h"

#include <algorithm>
#include <chrono>

namespace pneumo::perf {

namespace {
using Clock = std::chrono::steady_clock;
constexpr double kTriadBytesPerElement = 3 * sizeof(float);   // read b, read c, write a
}  // namespace

void triad_ref(float* a, const float* b, const float* c, float s, std::size_t n) {
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
}

Bandwidth summarize(std::vector<double> gb_s, std::size_t bytes_per_array) {
  Bandwidth b;
  b.bytes_per_array = bytes_per_array;
  b.repetitions = int(gb_s.size());
  if (gb_s.empty()) return b;
  std::sort(gb_s.begin(), gb_s.end());
  b.median_gb_s = gb_s[gb_s.size() / 2];
  b.min_gb_s = gb_s.front();
  b.max_gb_s = gb_s.back();
  return b;
}

Bandwidth measure_triad_native(std::size_t bytes_per_array, int reps) {
  const std::size_t n = bytes_per_array / sizeof(float);
  std::vector<float> a(n), b(n), c(n);
  // First touch in parallel so pages land where the threads run.
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i) { a[i] = 0.f; b[i] = 1.f; c[i] = 2.f; }
  std::vector<double> samples;
  for (int r = -1; r < reps; ++r) {
    const auto t0 = Clock::now();
    triad_ref(a.data(), b.data(), c.data(), 3.f, n);
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    if (r >= 0) samples.push_back(kTriadBytesPerElement * double(n) / s * 1e-9);
  }
  return summarize(samples, bytes_per_array);
}

Bandwidth measure_triad_opencl(ocl::Context& ctx, std::size_t bytes_per_array, int reps) {
  const std::size_t n = bytes_per_array / sizeof(float);
  ctx.check_fits(3 * n * sizeof(float), n * sizeof(float), "the bandwidth measurement");
  cl::Buffer a(ctx.context(), CL_MEM_READ_WRITE, n * sizeof(float));
  cl::Buffer b(ctx.context(), CL_MEM_READ_WRITE, n * sizeof(float));
  cl::Buffer c(ctx.context(), CL_MEM_READ_WRITE, n * sizeof(float));
  auto& q = ctx.queue();
  q.enqueueFillBuffer(b, 1.f, 0, n * sizeof(float));
  q.enqueueFillBuffer(c, 2.f, 0, n * sizeof(float));
  cl::Kernel k = ctx.kernel("stream_triad.cl", "stream_triad");
  k.setArg(0, a);
  k.setArg(1, b);
  k.setArg(2, c);
  k.setArg(3, 3.f);
  k.setArg(4, cl_uint(n));
  const std::size_t local = 256;
  const std::size_t global = (n + local - 1) / local * local;
  std::vector<double> samples;
  for (int r = -1; r < reps; ++r) {   // r = -1 warms the kernel (first launch compiles on PoCL)
    q.finish();
    const auto t0 = Clock::now();
    q.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global), cl::NDRange(local));
    q.finish();
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    if (r >= 0) samples.push_back(kTriadBytesPerElement * double(n) / s * 1e-9);
  }
  return summarize(samples, bytes_per_array);
}

}  // namespace pneumo::perf
