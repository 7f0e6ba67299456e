#pragma once
// How many CPU threads pneumo uses: its own loops (OpenMP) and PoCL's CPU device, which runs the
// OpenCL kernels on this machine. `--threads N` sets both, so a user who shares the machine (or
// benchmarks one core) says it once.
namespace pneumo {

inline constexpr int kMaxThreads = 1024;

/// Sets the count for OpenMP now and for PoCL's CPU device when it is first opened (PoCL reads
/// POCL_MAX_PTHREAD_COUNT, and from 4.0 POCL_CPU_MAX_CU_COUNT, when it creates the device), so call
/// it before any OpenCL platform is listed. InputError outside 1…kMaxThreads.
void set_thread_count(int threads);

}  // namespace pneumo
