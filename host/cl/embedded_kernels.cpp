#include "cl/embedded_kernels.h"

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace pneumo::ocl {

std::string kernel_source(const std::string& path) {
  std::string dir = PNEUMO_KERNEL_DIR;
  if (const char* env = std::getenv("PNEUMO_KERNEL_DIR")) dir = env;
  if (!dir.empty()) {
    std::ifstream in(dir + "/" + path, std::ios::binary);
    if (!in) throw std::runtime_error("kernel " + path + " not found in PNEUMO_KERNEL_DIR=" + dir);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  for (const auto& k : embedded_kernels())
    if (path == k.path) return k.source;
  throw std::runtime_error("no embedded kernel named " + path);
}

}  // namespace pneumo::ocl
