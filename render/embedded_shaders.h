#pragma once
// shaders/* embedded into the library at build time (cmake/EmbedKernels.cmake).
#include <string>
#include <vector>

#include "core/embedded_files.h"

namespace pneumo::gl {

using EmbeddedShader = EmbeddedFile;   // path relative to shaders/, e.g. "raycast.frag"

const std::vector<EmbeddedShader>& embedded_shaders();

/// The source of shaders/<path>. With PNEUMO_SHADER_DIR set at configure time (or the environment
/// variable of the same name at run time) the file is read from that folder instead, so shaders
/// can be edited without rebuilding. Throws std::runtime_error if there is no such shader.
std::string shader_source(const std::string& path);

}  // namespace pneumo::gl
