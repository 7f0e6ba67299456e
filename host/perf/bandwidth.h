#pragma once
// The machine's memory bandwidth, measured by STREAM's triad (a = b + s·c), natively with OpenMP
// and as an OpenCL kernel on a device. Every roofline ratio pneumo reports divides by a figure
// measured in the same run, because this machine's bandwidth swings with other load.
#include <cstdint>
#include <vector>

#include "cl/cl_runtime.h"

namespace pneumo::perf {

/// The plain reference of kernels/stream_triad.cl.
void triad_ref(float* a, const float* b, const float* c, float s, std::size_t n);

struct Bandwidth {
  double median_gb_s = 0, min_gb_s = 0, max_gb_s = 0;   // 1 GB = 1e9 bytes; triad moves 12 bytes per element
  int repetitions = 0;
  std::size_t bytes_per_array = 0;
};

/// Triad over three arrays of `bytes_per_array` each, repeated `reps` times (after one warm-up).
Bandwidth measure_triad_native(std::size_t bytes_per_array, int reps);
Bandwidth measure_triad_opencl(ocl::Context& ctx, std::size_t bytes_per_array, int reps);

/// Median, minimum and maximum of samples (in place sort).
Bandwidth summarize(std::vector<double> gb_s, std::size_t bytes_per_array);

}  // namespace pneumo::perf
