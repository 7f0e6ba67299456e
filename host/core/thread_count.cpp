#include "core/thread_count.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>

#include "core/error.h"
#include "core/log.h"

namespace pneumo {

namespace {

bool g_count_fixed = false;

}  // namespace

void set_thread_count(int threads) {
  if (threads < 1 || threads > kMaxThreads)
    throw InputError("--threads " + std::to_string(threads) + ": must be 1 to " + std::to_string(kMaxThreads));
  omp_set_num_threads(threads);
  g_count_fixed = true;
  const std::string n = std::to_string(threads);
  setenv("POCL_MAX_PTHREAD_COUNT", n.c_str(), 1);  // PoCL up to 3.x (Debian 12 ships 3.1)
  setenv("POCL_CPU_MAX_CU_COUNT", n.c_str(), 1);   // PoCL 4 and later
  log::debug("CPU threads: " + n + " (OpenMP loops and PoCL's CPU device)");
}

int cores_left(int usable, std::vector<int> others_samples) {
  usable = std::max(usable, 1);
  if (others_samples.empty()) return usable;
  std::nth_element(others_samples.begin(), others_samples.begin() + others_samples.size() / 2,
                   others_samples.end());
  return std::clamp(usable - others_samples[others_samples.size() / 2], 1, usable);
}

int runnable_tasks(const char* line) {
  double l1, l5, l15;
  int running = -1, total = 0;
  if (std::sscanf(line, "%lf %lf %lf %d/%d", &l1, &l5, &l15, &running, &total) != 5) return -1;
  return running;
}

char task_state(const char* stat_line) {
  const char* close = std::strrchr(stat_line, ')');   // the name in parentheses may hold ')' itself
  if (!close || close[1] != ' ' || close[2] == '\0') return '?';
  return close[2];
}

int own_runnable_threads() {
  namespace fs = std::filesystem;
  std::error_code ec;
  int running = 0;
  // Incremented with an error code: a range-for's ++ would throw from the start of a stage.
  for (fs::directory_iterator it("/proc/self/task", ec), end; !ec && it != end; it.increment(ec)) {
    FILE* f = std::fopen((it->path() / "stat").c_str(), "r");
    if (!f) continue;   // a thread that ended since the listing
    char line[512] = {};
    const bool read = std::fgets(line, sizeof line, f) != nullptr;
    std::fclose(f);
    if (read && task_state(line) == 'R') ++running;
  }
  return ec ? -1 : running;
}

void fit_threads_to_load() {
  if (g_count_fixed || std::getenv("OMP_NUM_THREADS")) return;
  const int usable = omp_get_num_procs();   // the CPUs of this process's affinity
  std::vector<int> samples;
  for (int i = 0; i < 5; ++i) {
    if (i > 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    // Our own threads are not load: OpenMP's workers spin for a while after each loop, and the
    // sampling thread itself is running (all we can take off when /proc/self/task is unreadable).
    // Ours are read first: no parallel loop runs here, so a worker can only fall asleep between
    // the two reads, which makes `others` too small by one at most (and a negative count is 0),
    // never too large.
    const int own = std::max(own_runnable_threads(), 1);
    FILE* f = std::fopen("/proc/loadavg", "r");
    if (!f) break;
    char line[256] = {};
    const bool read = std::fgets(line, sizeof line, f) != nullptr;
    std::fclose(f);
    const int n = read ? runnable_tasks(line) : -1;
    if (n < 0) continue;
    samples.push_back(std::max(n - own, 0));
  }
  const int threads = cores_left(usable, samples);
  omp_set_num_threads(threads);
  log::debug("CPU threads: " + std::to_string(threads) + " of " + std::to_string(usable) +
             (threads < usable ? " (other processes keep the rest busy)" : ""));
}

}  // namespace pneumo
