#pragma once
// How much memory this process may still take, and a refusal before an allocation that cannot fit.
// A mesh of 1-voxel cubes on a 100 M-voxel CT needs tens of GB; without a check it ran for seconds
// and ended "out of memory" with no figure. The check compares an estimate with the tightest of
// the limits the process meets: its address-space limit (ulimit -v), its control group's
// memory.max (containers), and the memory the kernel says it can still hand out (MemAvailable
// plus free swap).
#include <cstdint>
#include <string>

namespace pneumo {

struct MemoryBudget {
  uint64_t bytes = UINT64_MAX;   // what may still be allocated; UINT64_MAX when nothing could be read
  std::string limited_by;        // which limit that is, in words a user can act on
};

/// The tightest limit now, from /proc/self/statm, getrlimit, /sys/fs/cgroup and /proc/meminfo.
MemoryBudget available_memory();

/// "1.2 GiB", "340 MiB".
std::string format_bytes(uint64_t bytes);

/// InputError (exit 2) when `bytes_needed` exceeds `budget`: "<what> needs about X; about Y is
/// available (<limit>); <advice>". Pure, so the rule is tested without exhausting a machine.
void require_memory(uint64_t bytes_needed, const MemoryBudget& budget, const std::string& what,
                    const std::string& advice);
/// The same against available_memory().
void require_memory(uint64_t bytes_needed, const std::string& what, const std::string& advice);

}  // namespace pneumo
