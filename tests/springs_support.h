#pragma once
// Nimura's mass-spring lattice (scene.h use_nimura_springs), pneumo's material before the finite elements
// became the default (2026-12-06), for scenes written as JSON: the tests of what only the springs do (the
// explicit, Newmark and 2004 schemes, Kitasaka's volume term, spring inversion). A parsed scene takes
// use_nimura_springs() itself.
#include <nlohmann/json.hpp>

#include "scene/scene.h"

namespace pneumo::testing_support {

/// The whole "material" section of that lattice, every key written out: the default scene's, passed through
/// use_nimura_springs() and echoed, so it cannot drift from the library's definition.
inline nlohmann::json springs_material_json() {
  Scene s = default_scene();
  use_nimura_springs(s.material);
  return s.echo().at("material");
}

}  // namespace pneumo::testing_support
