// The solver's ETA (solver_common.h, solver_eta): a residual decaying geometrically gets the closed
// form's time to the tolerance; a residual that dips for a few samples but has not fallen over the
// last twenty, or falls too slowly, gets the time left to solver.max_steps, flagged, never less (a
// run of 65,000 steps once showed "ETA ~0.1 s" throughout).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "solve/solver_common.h"

namespace pneumo::detail {
namespace {

std::vector<SolveSample> history(int samples, int every, double (*residual)(int64_t step)) {
  std::vector<SolveSample> h;
  for (int i = 1; i <= samples; ++i) {
    SolveSample s;
    s.step = int64_t(i) * every;
    s.residual = residual(s.step);
    h.push_back(s);
  }
  return h;
}

TEST(SolverEta, GeometricDecayGivesTheClosedFormsTimeToTheTolerance) {
  // r = e^(−0.01 step): from step 300 (r = e^−3) to 1e-3 takes (ln 1e3 − 3) / 0.01 = 390.8 steps.
  const auto h = history(30, 10, [](int64_t step) { return std::exp(-0.01 * double(step)); });
  const SolverEta eta = solver_eta(h, 1e-3, 1000000, 2e-3);
  const double expected = (std::log(1e3) - 3.0) / 0.01 * 2e-3;
  EXPECT_NEAR(eta.seconds, expected, 1e-9 * expected);
  EXPECT_FALSE(eta.step_limit);
}

TEST(SolverEta, ADipOfAnOscillatingResidualPromisesNothingBeyondTheStepBudget) {
  // Rising over the last 20 samples, falling over the last 5: the budget bounds it.
  const auto h = history(40, 10, [](int64_t step) {
    return 1e-2 * std::exp(0.002 * double(step)) * (step > 350 ? 1.0 - 0.05 * double(step - 350) / 10.0 : 1.0);
  });
  const SolverEta eta = solver_eta(h, 1e-3, 2000, 1e-3);
  EXPECT_TRUE(eta.step_limit);
  EXPECT_DOUBLE_EQ(eta.seconds, (2000 - 400) * 1e-3);
}

TEST(SolverEta, OfTwoFallingRatesTheSlowerIsTaken) {
  // Falling at 0.001 per step up to step 350, then at 0.01: the last 5 samples (steps 360-400) fall
  // at 0.01, the last 20 (210-400) at (14 × 0.001 + 5 × 0.01) / 19 per step.
  const auto h = history(40, 10, [](int64_t step) {
    const double s = double(step);
    return std::exp(-(s <= 350 ? 0.001 * s : 0.35 + 0.01 * (s - 350)));
  });
  const double slower = (140 * 0.001 + 50 * 0.01) / 190.0;
  const double r_now = std::exp(-(0.35 + 0.5));
  const SolverEta eta = solver_eta(h, 1e-3, 1000000, 1e-3);
  const double expected = (std::log(r_now) - std::log(1e-3)) / slower * 1e-3;
  EXPECT_NEAR(eta.seconds, expected, 1e-9 * expected);
  EXPECT_FALSE(eta.step_limit);
}

TEST(SolverEta, ASlowFallIsCappedAtTheStepBudgetAndFewSamplesGiveNone) {
  const auto slow = history(30, 10, [](int64_t step) { return std::exp(-1e-5 * double(step)); });
  const SolverEta eta = solver_eta(slow, 1e-3, 1000, 1e-3);
  EXPECT_TRUE(eta.step_limit);
  EXPECT_DOUBLE_EQ(eta.seconds, (1000 - 300) * 1e-3);
  EXPECT_LT(solver_eta(history(3, 10, [](int64_t) { return 1.0; }), 1e-3, 1000, 1e-3).seconds, 0.0);
  EXPECT_LT(solver_eta(history(30, 10, [](int64_t) { return 1e-4; }), 1e-3, 1000, 1e-3).seconds, 0.0)
      << "at the tolerance already: no estimate";
}

TEST(SolverEta, ALoadIncrementIsNotReadAsDivergence) {
  // A static scheme's load in three increments (4, 8, 12 mmHg as Pa 533, 1067, 1600), each solved
  // to 1e-3 and then raised, the residual jumping back to 0.5. Before the last increment: the time so
  // far (step × s/step) scaled by the load still to apply, (1600 − 1067) / 1067 of it, not the step
  // budget. Two samples into the last increment: no estimate yet (the jump is not a rising residual).
  // Five samples into it: the decay of this increment alone, closed form as above.
  std::vector<SolveSample> h;
  int64_t step = 0;
  for (double p : {533.0, 1067.0}) {
    for (int i = 0; i < 8; ++i) {
      SolveSample s;
      s.step = ++step;
      s.pressure_pa = p;
      s.residual = 0.5 * std::pow(0.3, i);
      h.push_back(s);
    }
  }
  const SolverEta mid = solver_eta(h, 1e-3, 1000000, 2.0, 0.0, 1600.0);
  EXPECT_FALSE(mid.step_limit);
  EXPECT_NEAR(mid.seconds, 16 * 2.0 * (1600.0 - 1067.0) / 1067.0, 1e-9);
  for (int i = 0; i < 5; ++i) {
    SolveSample s;
    s.step = ++step;
    s.pressure_pa = 1600.0;
    s.residual = 0.5 * std::pow(0.3, i);
    h.push_back(s);
    const SolverEta eta = solver_eta(h, 1e-3, 1000000, 2.0, 0.0, 1600.0);
    EXPECT_FALSE(eta.step_limit) << "sample " << i;
    if (i < 4) {
      EXPECT_LT(eta.seconds, 0.0) << "sample " << i;
    } else {
      const double expected = (std::log(1e-3) - std::log(0.5 * std::pow(0.3, 4))) / std::log(0.3) * 2.0;
      EXPECT_NEAR(eta.seconds, expected, 1e-9 * expected);
    }
  }
}

}  // namespace
}  // namespace pneumo::detail
