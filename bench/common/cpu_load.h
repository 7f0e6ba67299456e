#pragma once
// Contention on a shared machine: how much CPU other processes used while something was timed.
// Linux /proc; the readings are −1 elsewhere. Used by the Google Benchmark binaries and `pneumo bench`.
#include <chrono>

#include <nlohmann/json.hpp>

namespace pneumo::bench {

struct CpuSample {
  // All CPUs' busy time; this process's (all its threads, PoCL's included) and its children's that it has
  // waited for (`pneumo bench --pipeline` times `pneumo run` as a child).
  double busy_s = -1.0, own_s = -1.0;
  std::chrono::steady_clock::time_point t = std::chrono::steady_clock::now();
};

CpuSample cpu_sample();

/// Cores' worth of CPU that other processes used between a and b (e.g. 0.9: another job held a core);
/// −1 when /proc could not be read. Above ~0.1 a timing was contended.
double other_cores(const CpuSample& a, const CpuSample& b);

/// The 1, 5 and 15 minute load averages (/proc/loadavg; −1 when unreadable).
struct LoadAverage {
  double one = -1, five = -1, fifteen = -1;
};
LoadAverage load_average();
/// [1, 5, 15 min] as a JSON array.
nlohmann::json to_json(const LoadAverage& l);

}  // namespace pneumo::bench
