// `pneumo validate pressure-volume` (pipeline/pressure_volume_study.h) on the tiny case.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "io_test_support.h"
#include "pipeline/pressure_volume_study.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using testing_support::ScratchDir;
using testing_support::write_tiny_case;

TEST(PressureVolumeStudy, CurveComplianceAndFraction) {
  // Compared: the tiny case at the default pressures (0 … 30 mmHg), against what the study's fields mean:
  // one converged point per pressure in increasing order, 0 ml at 0 mmHg, the volume rising with pressure,
  // compliance = (V(15) − V(5)) / 10 and fraction = V(15) / V(30) from those points (exact: the same
  // numbers); the default material's fraction above 0.6 (stiffening; patients 0.67, docs/fidelity.md
  // §4), and Nimura's linear lattice's near a linear wall's ½ (0.4 … 0.6: geometric nonlinearity only). Pressures without 5, 15 or 30 mmHg are an
  // InputError before anything is solved.
  ScratchDir d;
  const Scene scene = load_scene(write_tiny_case(d));
  const PressureVolumeStudy s = pressure_volume_study(scene, default_pressure_volume_pressures());
  ASSERT_EQ(s.curve.size(), default_pressure_volume_pressures().size());
  EXPECT_TRUE(s.all_converged);
  EXPECT_EQ(s.curve.front().cavity_volume_ml, 0.0);
  double v5 = 0, v15 = 0, v30 = 0;
  for (std::size_t i = 1; i < s.curve.size(); ++i) {
    EXPECT_GT(s.curve[i].pressure_mmhg, s.curve[i - 1].pressure_mmhg);
    EXPECT_GT(s.curve[i].cavity_volume_ml, s.curve[i - 1].cavity_volume_ml);
    if (s.curve[i].pressure_mmhg == 5) v5 = s.curve[i].cavity_volume_ml;
    if (s.curve[i].pressure_mmhg == 15) v15 = s.curve[i].cavity_volume_ml;
    if (s.curve[i].pressure_mmhg == 30) v30 = s.curve[i].cavity_volume_ml;
  }
  EXPECT_DOUBLE_EQ(s.compliance_ml_per_mmhg, (v15 - v5) / 10.0);
  EXPECT_DOUBLE_EQ(s.fraction_of_30_at_15, v15 / v30);
  // The default stiffens (Demiray's b = 10): the curve bends as patients' does (≥ 0.6, McDougall 0.67).
  EXPECT_GT(s.fraction_of_30_at_15, 0.6);
  EXPECT_LT(s.fraction_of_30_at_15, 0.9);
  EXPECT_THROW(pressure_volume_study(scene, {0, 5, 15, 20}), InputError);

  // Nimura's linear springs: near a linear wall's ½.
  Scene springs = scene;
  use_nimura_springs(springs.material);
  springs.solver.method = SolverMethod::Static;
  const PressureVolumeStudy linear = pressure_volume_study(springs, default_pressure_volume_pressures());
  EXPECT_TRUE(linear.all_converged);
  EXPECT_GT(linear.fraction_of_30_at_15, 0.4);
  EXPECT_LT(linear.fraction_of_30_at_15, 0.6);
}


TEST(PressureVolumeStudy, PressuresAScenesCurveWouldRefuseAreRefused) {
  // Each pressure is checked as a scene's pressure curve is (0 for rest, else 0.1–100 mmHg): a negative
  // one would "converge" to a negative cavity, a NaN or an absurd one to nonsense. Refused before any
  // solve, naming the option.
  ScratchDir d;
  const Scene scene = load_scene(write_tiny_case(d));
  for (const std::vector<double>& bad : {std::vector<double>{-5, 5, 15, 30}, {0, 5, 15, 30, NAN},
                                         {0, 5, 15, 30, 1e6}, {0, 0.05, 5, 15, 30}}) {
    try {
      pressure_volume_study(scene, bad);
      ADD_FAILURE() << "accepted " << bad.front() << " … " << bad.back();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--pressures-mmhg"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace pneumo
