#include "core/thread_count.h"

#include <omp.h>

#include <cstdlib>
#include <string>

#include "core/error.h"
#include "core/log.h"

namespace pneumo {

void set_thread_count(int threads) {
  if (threads < 1 || threads > kMaxThreads)
    throw InputError("--threads " + std::to_string(threads) + ": must be 1 to " + std::to_string(kMaxThreads));
  omp_set_num_threads(threads);
  const std::string n = std::to_string(threads);
  setenv("POCL_MAX_PTHREAD_COUNT", n.c_str(), 1);  // PoCL up to 3.x (Debian 12 ships 3.1)
  setenv("POCL_CPU_MAX_CU_COUNT", n.c_str(), 1);   // PoCL 4 and later
  log::debug("CPU threads: " + n + " (OpenMP loops and PoCL's CPU device)");
}

}  // namespace pneumo
