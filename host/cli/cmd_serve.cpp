#include <memory>

#include "cli/commands.h"
#include "render/gl_context.h"
#include "serve/http_server.h"

namespace pneumo::cli {

Run add_serve(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "serve", "A local web page over one case: re-inflate, aim the laparoscope, place ports on the skin (issue 22)");
  struct Opts { std::string scene, host = "127.0.0.1", out = "out/serve", backend = "auto"; int port = 8080; };
  auto o = std::make_shared<Opts>();
  cmd->add_option("scene", o->scene, "Scene .json: the case, loaded once")->required();
  cmd->add_option("--host", o->host, "Address to listen on (default 127.0.0.1: this machine only)");
  cmd->add_option("--port", o->port, "Port to listen on; 0 picks a free one")->check(CLI::Range(0, 65535));
  cmd->add_option("--out", o->out, "Folder for the plans the page saves and their reports");
  cmd->add_option("--backend", o->backend, "Offscreen OpenGL: auto, egl-device, egl-surfaceless or osmesa");
  return [=] {
    serve::ServeOptions opt;
    opt.scene_path = o->scene;
    opt.host = o->host;
    opt.port = o->port;
    opt.out_dir = o->out;
    opt.backend = parse_gl_backend(o->backend);
    return serve::serve_until_signalled(opt);
  };
}

}  // namespace pneumo::cli
