// `pneumo validate convergence` (pipeline/convergence_study.h): the observed order against closed
// forms, and the study on a small scene.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "pipeline/convergence_study.h"
#include "io_test_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using testing_support::ScratchDir;
using testing_support::write_tiny_case;

TEST(ConvergenceStudy, ObservedOrderOfClosedForms) {
  // Compared: f(h) = 3 + 2·hᵖ sampled at h = 12, 9, 6, 3 (the ratios of cube sizes 4, 3, 2, 1 voxels:
  // not constant) for p = 1 and 2, against p and f₀ = 3. Tolerance 1e-6 (bisection to 2⁻²⁰⁰ of the bracket,
  // then rounding). A sequence whose differences change sign has no order: monotone false, f₀ = finest.
  const std::vector<double> h{12, 9, 6, 3};
  for (const double p : {1.0, 2.0}) {
    std::vector<double> f;
    for (double x : h) f.push_back(3.0 + 2.0 * std::pow(x, p));
    const ObservedOrder o = observed_order(h, f);
    EXPECT_TRUE(o.monotone);
    EXPECT_NEAR(o.order, p, 1e-6);
    EXPECT_NEAR(o.extrapolated, 3.0, 1e-6);
  }
  const ObservedOrder zigzag = observed_order(h, {5.0, 4.0, 4.5, 4.2});
  EXPECT_FALSE(zigzag.monotone);
  EXPECT_EQ(zigzag.extrapolated, 4.2);
}

TEST(ConvergenceStudy, SolvesEachCubeSizeAndRefusesBadLists) {
  // Compared: the tiny case (16×16×10 voxels of 5 mm) studied at L = 2 and 1: one converged row per
  // size, in the order given, cube_mm = L × 5 mm, positive rise and gas volume, viscera nearly still; a list that is not
  // decreasing, or holds fewer than 2 sizes, is an InputError before anything is solved.
  ScratchDir d;
  const Scene scene = load_scene(write_tiny_case(d));
  const ConvergenceStudy s = convergence_study(scene, {2, 1});
  ASSERT_EQ(s.rows.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(s.rows[i].cube_voxels, int(2 - i));
    EXPECT_DOUBLE_EQ(s.rows[i].cube_mm, 5.0 * (2 - i));
    EXPECT_TRUE(s.rows[i].converged);
    EXPECT_GT(s.rows[i].anterior_rise_mm, 0.0);
    EXPECT_GT(s.rows[i].cavity_volume_ml, 0.0);
    // The tiny case's viscera lie on its fixed floor: they barely move, far less than the wall rises.
    EXPECT_LT(std::abs(s.rows[i].viscera_posterior_motion_mm), 0.1 * s.rows[i].anterior_rise_mm);
  }
  EXPECT_THROW(convergence_study(scene, {1, 2}), InputError);
  EXPECT_THROW(convergence_study(scene, {2}), InputError);
}

}  // namespace
}  // namespace pneumo
