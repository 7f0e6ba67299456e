#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "render/embedded_shaders.h"

namespace pneumo::gl {

std::string shader_source(const std::string& path) {
  std::string dir = PNEUMO_SHADER_DIR;
  if (const char* env = std::getenv("PNEUMO_SHADER_DIR")) dir = env;
  if (!dir.empty()) {
    std::ifstream in(dir + "/" + path, std::ios::binary);
    if (!in) throw std::runtime_error("shader " + path + " not found in PNEUMO_SHADER_DIR=" + dir);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  for (const auto& s : embedded_shaders())
    if (path == s.path) return s.source;
  throw std::runtime_error("no embedded shader named " + path);
}

}  // namespace pneumo::gl
