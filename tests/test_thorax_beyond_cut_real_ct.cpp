// The chest beyond the real CT's cranial cut (material.thorax_compliance_l_per_cmh2o,
// solve/thorax_beyond_cut.h), as a user turning it on would run it: the example's inputs, 12 mmHg and
// the lungs' compliance. The CT's top slice cuts the liver, the spleen, the stomach and the lung bases.
//
// Checked against what lies outside the code: Loring et al. 2014 (J Appl Physiol 117:1074) measured
// the oesophageal (pleural) pressure of 19 ventilated patients at end-expiration before and during a
// 20 cmH2O pneumoperitoneum and found no significant change (8.7 ± 3.4 against 7.6 ± 3.2 cmH2O), so
// the pleural pressure the face raises must lie within their scatter, 0 to 3.4 cmH2O, at the lower
// 12 mmHg (16 cmH2O). And the face moves into the chest (ΔV > 0), as the gas pushes the viscera.
// The earlier answers hold: a converged run with no inverted tetrahedron and a rise in the adult
// 25–60 mm.
#include <gtest/gtest.h>

#include "example_roles_support.h"
#include "scene_run_support.h"

using namespace pneumo::testing_support;

TEST(ThoraxBeyondCutOnTheRealCt, TheCutFaceMovesIntoTheChestWithAPleuralPressureInPatientsScatter) {
  PNEUMO_REQUIRE_REAL_CT();
  ScratchDir dir;
  nlohmann::json scene = {{"name", "chest"}, {"load", {{"pressure_mmhg", 12}}},
                          {"material", {{"thorax_compliance_l_per_cmh2o", 0.12}}}};
  scene["inputs"] = {{"ct", example_ct_path()}, {"labels", example_labels_path()}};
  const SceneRun run = run_scene(dir, "chest", scene);
  ASSERT_EQ(run.code, 0) << run.err;
  const nlohmann::json& m = run.metrics;
  EXPECT_TRUE(m["converged"].get<bool>()) << m["stop_reason"];
  EXPECT_EQ(m["inverted_tetrahedra"].get<int>(), 0);
  EXPECT_GE(m["anterior_rise_mm"].get<double>(), 25.0);
  EXPECT_LE(m["anterior_rise_mm"].get<double>(), 60.0);
  ASSERT_TRUE(m.contains("thorax_nodes"));
  EXPECT_GT(m["thorax_nodes"].get<int>(), 100);
  const double c = m["thorax_compliance_l_per_cmh2o"].get<double>();
  const double dv_ml = m["thorax_volume_change_ml"].get<double>(), p = m["thorax_pressure_cmh2o"].get<double>();
  // The lungs in view (about 0.1 L of a 2 L lung) leave most of the compliance beyond the cut.
  EXPECT_GT(c, 0.9 * 0.12);
  EXPECT_LT(c, 0.12);
  EXPECT_GT(dv_ml, 0.0);
  EXPECT_LT(p, 3.4);
}
