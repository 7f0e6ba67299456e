#include "cl/embedded_kernels.h"

namespace pneumo::ocl {

std::string kernel_source(const std::string& path) {
  return embedded_source(embedded_kernels(), path, "kernel", PNEUMO_KERNEL_DIR, "PNEUMO_KERNEL_DIR");
}

}  // namespace pneumo::ocl
