#pragma once
// Source files embedded into the library at build time (cmake/EmbedKernels.cmake): the OpenCL
// kernels (cl/embedded_kernels.h) and the GLSL shaders (render/embedded_shaders.h) share this table
// type and its one look-up.
#include <string>
#include <vector>

namespace pneumo {

struct EmbeddedFile {
  const char* path;   // relative to its folder, e.g. "warp.cl", "common/math.cl", "raycast.frag"
  std::string source;
};

/// The source of `path`: read from a folder when one is set (the environment variable `env_var`,
/// else `configured_dir`, the configure-time value; "" = none), so sources can be edited without
/// rebuilding; otherwise the embedded `table`'s copy. `what` ("kernel", "shader") names it in the
/// std::runtime_error thrown when there is no such file.
std::string embedded_source(const std::vector<EmbeddedFile>& table, const std::string& path, const char* what,
                            const char* configured_dir, const char* env_var);

}  // namespace pneumo
