#include "render/gl_api.h"

#include <cstdio>
#include <stdexcept>

namespace pneumo::gl {
namespace {
Api g_api;
}

const Api& api() { return g_api; }

void load_api(GetProc get_proc) {
  Api loaded;
#define PNEUMO_GL_LOAD(name, type)                                                        \
  loaded.name = reinterpret_cast<type>(get_proc("gl" #name));                             \
  if (!loaded.name) throw std::runtime_error("OpenGL function gl" #name " is not available");
  PNEUMO_GL_FUNCTIONS(PNEUMO_GL_LOAD)
#undef PNEUMO_GL_LOAD
  g_api = loaded;
}

void check_error(const std::string& where) {
  if (!g_api.GetError) throw std::runtime_error(where + ": no OpenGL context");
  const GLenum e = g_api.GetError();
  if (e == GL_NO_ERROR) return;
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", e);
  throw std::runtime_error(where + ": OpenGL error " + code);
}

}  // namespace pneumo::gl
