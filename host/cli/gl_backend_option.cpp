#include "cli/gl_backend_option.h"

#include "cli/option_check.h"
#include "render/gl_context.h"

namespace pneumo::cli {

CLI::Option* add_gl_backend_option(CLI::App* cmd, std::string& backend, const std::string& what) {
  return cmd
      ->add_option("--backend", backend,
                   "Offscreen OpenGL for " + what + ": " + gl_backend_names() +
                       " (auto: a GPU's EGL device, else EGL without a display, else OSMesa)")
      ->capture_default_str()
      ->check(checked_by([](const std::string& value) { (void)parse_gl_backend(value); }, "backend"));
}

}  // namespace pneumo::cli
