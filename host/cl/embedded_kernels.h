#pragma once
// kernels/*.cl embedded into the library at build time (cmake/EmbedKernels.cmake).
#include <string>
#include <vector>

#include "core/embedded_files.h"

namespace pneumo::ocl {

using EmbeddedKernel = EmbeddedFile;   // path relative to kernels/, e.g. "common/math.cl"

const std::vector<EmbeddedKernel>& embedded_kernels();

/// The source of kernels/<path>. With PNEUMO_KERNEL_DIR set at configure time (or the environment
/// variable of the same name at run time) the file is read from that folder instead, so kernels
/// can be edited without rebuilding. Throws std::runtime_error if there is no such kernel.
std::string kernel_source(const std::string& path);

}  // namespace pneumo::ocl
