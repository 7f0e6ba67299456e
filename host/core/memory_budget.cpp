#include "core/memory_budget.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace pneumo {

namespace {

/// A number from a one-value file such as memory.max; nullopt-like UINT64_MAX for "max" or absent.
uint64_t read_single_value(const std::string& path) {
  std::ifstream f(path);
  std::string s;
  if (!(f >> s) || s == "max") return UINT64_MAX;
  try {
    return std::stoull(s);
  } catch (...) {
    return UINT64_MAX;
  }
}

/// A "Key: N kB" field of /proc/meminfo in bytes; UINT64_MAX when absent.
uint64_t meminfo_bytes(const std::string& key) {
  std::ifstream f("/proc/meminfo");
  std::string line;
  while (std::getline(f, line)) {
    if (line.compare(0, key.size() + 1, key + ":") != 0) continue;
    std::istringstream is(line.substr(key.size() + 1));
    uint64_t kib = 0;
    if (is >> kib) return kib * 1024;
  }
  return UINT64_MAX;
}

/// The address space this process already maps (VmSize), bytes.
uint64_t mapped_bytes() {
  std::ifstream f("/proc/self/statm");
  uint64_t pages = 0;
  if (!(f >> pages)) return 0;
  return pages * uint64_t(sysconf(_SC_PAGESIZE));
}

/// The cgroup (v2) this process belongs to: "0::/path" in /proc/self/cgroup.
std::string cgroup_dir() {
  std::ifstream f("/proc/self/cgroup");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("0::", 0) == 0) return "/sys/fs/cgroup" + line.substr(3);
  return {};
}

void tighten(MemoryBudget& b, uint64_t bytes, const char* why) {
  if (bytes < b.bytes) {
    b.bytes = bytes;
    b.limited_by = why;
  }
}

}  // namespace

MemoryBudget available_memory() {
  MemoryBudget b;
  rlimit as{};
  if (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) {
    const uint64_t used = mapped_bytes();
    tighten(b, as.rlim_cur > used ? as.rlim_cur - used : 0, "the address-space limit, ulimit -v");
  }
  const std::string cg = cgroup_dir();
  if (!cg.empty()) {
    const uint64_t max = read_single_value(cg + "/memory.max");
    const uint64_t current = read_single_value(cg + "/memory.current");
    if (max != UINT64_MAX && current != UINT64_MAX)
      tighten(b, max > current ? max - current : 0, "the control group's memory.max");
  }
  const uint64_t avail = meminfo_bytes("MemAvailable"), swap = meminfo_bytes("SwapFree");
  if (avail != UINT64_MAX) tighten(b, avail + (swap == UINT64_MAX ? 0 : swap), "the memory free on this machine");
  return b;
}

std::string format_bytes(uint64_t bytes) {
  char s[32];
  if (bytes >= (uint64_t(1) << 30))
    std::snprintf(s, sizeof s, "%.1f GiB", double(bytes) / double(uint64_t(1) << 30));
  else
    std::snprintf(s, sizeof s, "%.0f MiB", std::max(1.0, double(bytes) / double(1 << 20)));
  return s;
}

void require_memory(uint64_t bytes_needed, const MemoryBudget& budget, const std::string& what,
                    const std::string& advice) {
  if (bytes_needed <= budget.bytes) return;
  throw InputError(what + " needs about " + format_bytes(bytes_needed) + "; about " + format_bytes(budget.bytes) +
                   " is available (" + budget.limited_by + "); " + advice);
}

void require_memory(uint64_t bytes_needed, const std::string& what, const std::string& advice) {
  require_memory(bytes_needed, available_memory(), what, advice);
}

}  // namespace pneumo
