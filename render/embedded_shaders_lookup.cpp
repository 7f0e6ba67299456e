#include "render/embedded_shaders.h"

namespace pneumo::gl {

std::string shader_source(const std::string& path) {
  return embedded_source(embedded_shaders(), path, "shader", PNEUMO_SHADER_DIR, "PNEUMO_SHADER_DIR");
}

}  // namespace pneumo::gl
