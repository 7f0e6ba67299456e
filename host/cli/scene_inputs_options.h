#pragma once
// A CT on the command line instead of a scene file: `pneumo run --ct CT [--labels SEG] --out DIR`
// runs the case at every default (roles from the label map's names, padding found on the CT,
// 12 mmHg); with a scene, the options replace its inputs. Paths on the command line are relative
// to the current folder, as a shell user expects, not to the scene's folder.
#include <CLI/CLI.hpp>

#include <string>

#include "scene/scene.h"

namespace pneumo::cli {

struct SceneSource {
  std::string scene;                      // the scene file, "" for none
  std::string ct, labels, label_names;    // "" = not given
};

/// The positional scene (now optional) and --ct, --labels, --label-names on `cmd`.
void add_scene_source_options(CLI::App* cmd, SceneSource& s);

/// The scene: the file's (its inputs replaced by the options given), or, without a file, one of
/// --ct's inputs and every default. InputError (exit 2) when neither a scene nor --ct is given.
Scene load_scene_source(const SceneSource& s);

}  // namespace pneumo::cli
