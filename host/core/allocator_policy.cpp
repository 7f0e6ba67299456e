#include "core/allocator_policy.h"

#include <malloc.h>

#include <climits>

namespace pneumo {

void keep_freed_memory_for_reuse() {
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
}

}  // namespace pneumo
