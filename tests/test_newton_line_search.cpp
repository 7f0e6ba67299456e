// Newton's globalisation (solve_newton.cpp): backtracking on the total potential energy, not on |f|.
// Where a model has no equilibrium at the load, a line search on |f| stalls at a point that is no
// equilibrium and reports "no descent", which names nothing to change; on the energy the iterates
// follow Π down, leave the model's size, and the run says which parameters to change.
#include <gtest/gtest.h>

#include <string>

#include "core/progress.h"
#include "pipeline/simulate.h"
#include "solve/solver.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using testing_support::ScratchDir;

Simulation tiny(const nlohmann::json& material, double pressure_mmhg, const ScratchDir& dir) {
  nlohmann::json j = testing_support::tiny_case_scene_json();
  j["material"] = material;
  j["load"]["pressure_mmhg"] = pressure_mmhg;
  j["solver"]["method"] = "newton";
  Progress::set_enabled(false);
  return simulate_scene(load_scene(testing_support::write_tiny_case(dir, j)));
}

TEST(NewtonLineSearch, AModelWithoutEquilibriumNamesTheParameterToChange) {
  // The tiny case's wall and viscera of neo-Hookean tissue without stiffening at 4 kPa under 12 mmHg:
  // a neo-Hookean wall under gas pressure has a largest pressure it holds (as a rubber balloon), and
  // this is above it. Compared: the run must throw DivergedError naming load.pressure_mmhg and
  // material.young_kpa (the |f| line search instead stopped with "no descent" at 10.9 mm of rise).
  ScratchDir dir;
  try {
    const Simulation s = tiny({{"model", "fem-neohookean"}, {"stiffening", 0.0}, {"young_kpa", 4.0}}, 12.0, dir);
    ADD_FAILURE() << "no error; stopped as " << s.result.stop_reason << " after " << s.result.steps << " steps";
  } catch (const DivergedError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("load.pressure_mmhg"), std::string::npos) << what;
    EXPECT_NE(what.find("material.young_kpa"), std::string::npos) << what;
  }
}

TEST(NewtonLineSearch, TheSameModelBelowItsLimitConverges) {
  // The same tissue at 5 kPa holds 12 mmHg: Newton must converge there, with no inverted tetrahedron
  // (the energy line search must not trade the limit case's honesty for failing a solvable one).
  ScratchDir dir;
  const Simulation s = tiny({{"model", "fem-neohookean"}, {"stiffening", 0.0}, {"young_kpa", 5.0}}, 12.0, dir);
  EXPECT_TRUE(s.result.converged) << s.result.stop_reason;
  EXPECT_EQ(s.result.inverted_tetrahedra, 0);
  EXPECT_LT(s.result.steps, 20);
}

}  // namespace
}  // namespace pneumo
