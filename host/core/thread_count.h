#pragma once
// How many CPU threads pneumo uses: its own loops (OpenMP) and PoCL's CPU device, which runs the
// OpenCL kernels on this machine. `--threads N` sets both, so a user who shares the machine (or
// benchmarks one core) says it once.
//
// Without it, each stage starts on the cores that other processes leave free (fit_threads_to_load):
// the solver's loops meet at a barrier every fraction of a millisecond, so a thread that shares its
// core with a busy process holds the others up at each one, and two threads were 1.7 times slower
// than one beside a busy process (docs/performance.md, "A busy machine").
#include <vector>

namespace pneumo {

inline constexpr int kMaxThreads = 1024;

/// Sets the count for OpenMP now and for PoCL's CPU device when it is first opened (PoCL reads
/// POCL_MAX_PTHREAD_COUNT, and from 4.0 POCL_CPU_MAX_CU_COUNT, when it creates the device), so call
/// it before any OpenCL platform is listed. InputError outside 1…kMaxThreads. The count then stays.
void set_thread_count(int threads);

/// The cores left to this process: `usable` (those it may run on) less the median of samples of the
/// runnable tasks that are not this process's threads, within [1, usable].
int cores_left(int usable, std::vector<int> others_samples);

/// The runnable tasks in a /proc/loadavg line ("0.50 0.60 0.70 3/512 1234": 3), or −1 if the line
/// has no such field.
int runnable_tasks(const char* loadavg_line);

/// The state letter of a /proc/<pid>/task/<tid>/stat line ("123 (name) R 1 …": 'R'), or '?'.
char task_state(const char* stat_line);

/// This process's threads the kernel counts as runnable now (state R, the caller included), or −1
/// when /proc/self/task cannot be read.
int own_runnable_threads();

/// Unless the count is fixed (set_thread_count, or OMP_NUM_THREADS in the environment), OpenMP's
/// loops use cores_left() of the cores this process may use, from five reads of /proc/loadavg 2 ms
/// apart, each less own_runnable_threads() (OpenMP's workers spin for some milliseconds after each
/// loop, and count as runnable), until the next call. Called at the start of each stage; a stage's
/// count does not follow a load that starts during it. PoCL's device keeps the count it was opened with.
void fit_threads_to_load();

}  // namespace pneumo
