#pragma once
// Nimura's mass-spring lattice (scene.h use_nimura_springs), pneumo's material before the finite elements
// became the default (2026-12-06): linear springs, the viscera at the wall's modulus, no fat by HU. For the tests of what
// only the springs do (the explicit, Newmark and 2004 schemes, Kitasaka's volume term, spring inversion)
// and of the figures measured with them; the default material is tested where the physics is.
#include <nlohmann/json.hpp>

#include "scene/scene.h"

namespace pneumo::testing_support {

/// The "material" keys of that lattice, to merge into a scene's JSON.
inline nlohmann::json springs_material_json() {
  return {{"model", "msd"}, {"stiffening", 0.0}, {"fat_young_kpa", nullptr}, {"viscera_young_kpa", nullptr}};
}

/// The same on a parsed scene.
inline void use_springs(Scene& s) { use_nimura_springs(s.material); }

}  // namespace pneumo::testing_support
