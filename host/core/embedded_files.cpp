#include "core/embedded_files.h"

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace pneumo {

std::string embedded_source(const std::vector<EmbeddedFile>& table, const std::string& path, const char* what,
                            const char* configured_dir, const char* env_var) {
  std::string dir = configured_dir;
  if (const char* env = std::getenv(env_var)) dir = env;
  if (!dir.empty()) {
    std::ifstream in(dir + "/" + path, std::ios::binary);
    if (!in) throw std::runtime_error(std::string(what) + " " + path + " not found in " + env_var + "=" + dir);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  for (const EmbeddedFile& f : table)
    if (path == f.path) return f.source;
  throw std::runtime_error(std::string("no embedded ") + what + " named " + path);
}

}  // namespace pneumo
