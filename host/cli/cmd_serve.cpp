#include <memory>

#include "cli/commands.h"
#include "cli/gl_backend_option.h"
#include "render/gl_context.h"
#include "serve/http_server.h"

namespace pneumo::cli {

Run add_serve(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "serve", "A local web page over one case: re-inflate, aim the laparoscope, rank and place ports on the skin");
  // The options' defaults are ServeOptions' own (the help shows them).
  struct Opts { serve::ServeOptions serve; std::string backend = "auto"; };
  auto o = std::make_shared<Opts>();
  cmd->add_option("scene", o->serve.scene_path, "Scene .json: the case, loaded once")->required();
  cmd->add_option("--host", o->serve.host, "Address to listen on (127.0.0.1: this machine only)")->capture_default_str();
  cmd->add_option("--port", o->serve.port, "Port to listen on; 0 picks a free one")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  cmd->add_option("--out", o->serve.out_dir, "Folder for the plans the page saves and their reports")
      ->capture_default_str();
  add_gl_backend_option(cmd, o->backend, "the views");
  return [=] {
    serve::ServeOptions opt = o->serve;
    opt.backend = parse_gl_backend(o->backend);
    return serve::serve_until_signalled(opt);
  };
}

}  // namespace pneumo::cli
