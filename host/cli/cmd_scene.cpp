#include <iostream>

#include "cli/commands.h"
#include "core/error.h"
#include "scene/scene.h"

namespace pneumo::cli {

Run add_scene(CLI::App& app) {
  auto* cmd = app.add_subcommand("scene", "Check a scene file and print it resolved (defaults filled in), or print the reference of every key");
  struct Opts { std::string file; bool reference = false; };
  auto o = std::make_shared<Opts>();
  cmd->add_option("file", o->file, "A scene .json file to check");
  cmd->add_flag("--reference", o->reference, "Print the Markdown reference of every scene key (docs/scene_reference.md)");
  return [=] {
    if (o->reference) {
      std::cout << scene_reference_markdown();
      return 0;
    }
    if (o->file.empty()) throw InputError("scene: give a scene file to check, or --reference");
    const Scene s = load_scene(o->file);
    std::cout << s.echo().dump(2) << "\n";
    return 0;
  };
}

}  // namespace pneumo::cli
