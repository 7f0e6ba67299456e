#pragma once
// kernels/*.cl embedded into the library at build time (cmake/EmbedKernels.cmake).
#include <string>
#include <vector>

namespace pneumo::ocl {

struct EmbeddedKernel {
  const char* path;    // relative to kernels/, e.g. "stream_triad.cl" or "common/math.cl"
  std::string source;
};

const std::vector<EmbeddedKernel>& embedded_kernels();

/// The source of kernels/<path>. With PNEUMO_KERNEL_DIR set at configure time (or the environment
/// variable of the same name at run time) the file is read from that folder instead, so kernels
/// can be edited without rebuilding. Throws std::runtime_error if there is no such kernel.
std::string kernel_source(const std::string& path);

}  // namespace pneumo::ocl
