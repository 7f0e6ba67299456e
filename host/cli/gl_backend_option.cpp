#include "cli/gl_backend_option.h"

#include "core/error.h"
#include "render/gl_context.h"

namespace pneumo::cli {

namespace {
std::string backend_names() {
  std::string names;
  for (GlBackend b : {GlBackend::Auto, GlBackend::EglDevice, GlBackend::EglSurfaceless, GlBackend::OSMesa})
    names += (names.empty() ? "" : ", ") + std::string(gl_backend_name(b));
  return names;
}
}  // namespace

CLI::Option* add_gl_backend_option(CLI::App* cmd, std::string& backend, const std::string& what) {
  return cmd
      ->add_option("--backend", backend,
                   "Offscreen OpenGL for " + what + ": " + backend_names() +
                       " (auto: a GPU's EGL device, else EGL without a display, else OSMesa)")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& value) -> std::string {
            try {
              (void)parse_gl_backend(value);
              return "";
            } catch (const InputError& e) {
              return e.what();
            }
          },
          "BACKEND", "backend"));
}

}  // namespace pneumo::cli
