// Static equilibrium by Newton's method with matrix-free preconditioned conjugate gradients, on any
// force field (force_field.h): the springs or the finite elements (issue "Bano's row").
//
// Each Newton iteration solves K d = f(x) for the step d (newton_linear_solver.h: on the host, or on
// the OpenCL device that holds the force field), with K = −∂f/∂x the stiffness at x (the
// force field's elastic part and the gas pressure's, pressure_stiffness.h), by CG preconditioned with
// the inverse 3×3 diagonal blocks of K (block Jacobi), to a relative residual η chosen as Eisenstat &
// Walker (1996, choice 2: η = 0.9 (|f_k|/|f_{k−1}|)², within [10⁻³, 0.1]), so early iterations are
// cheap and late ones converge fast. A backtracking line search halves the step until |f| falls
// (sufficient decrease, 10⁻⁴) and no further tetrahedron inverts. The load is applied in the static
// solver's increments, each solved before the next.
//
// Why the pressure's stiffness is in K: with soft fat (a few kPa) the wall's stiffness is of the order
// of the gas pressure's (1.6 kPa at 12 mmHg); without it Newton degrades to a linearly converging
// method (on the real CT with the Demiray law: 50 iterations against 17, docs/fem.md).
//
// Where K is indefinite (compressed springs, the co-rotational stress term under compression, the
// pressure on a wall near its limit point) CG meets a direction of non-positive curvature; then
// K + σ D is solved instead, D the diagonal blocks of K, σ growing tenfold from 10⁻³ until CG completes
// (a Levenberg–Marquardt shift towards scaled steepest descent) and shrinking tenfold after each full
// step.
#include <algorithm>
#include <cmath>

#include "solve/conjugate_gradients.h"
#include "solve/force_field.h"
#include "solve/newton_linear_solver.h"
#include "solve/solver_common.h"

namespace pneumo {

SolveResult solve_newton(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x) {
  const std::unique_ptr<ForceField> field = make_force_field(m, opt.forces);
  return solve_newton_on(m, opt, *field, x);
}

SolveResult solve_newton_on(const Mesh& m, const SolveOptions& opt, ForceField& field,
                            const std::vector<Vec3>& x_start) {
  std::vector<Vec3> x = x_start.empty() ? m.rest_m : x_start;
  SolveResult r;
  detail::Monitor mon(m, opt, "newton", r);
  const int64_t N = m.node_count();
  ForceModel model = opt.forces;
  model.damping = false;
  const int increments = detail::load_increments(opt);
  const std::string advice = detail::kLoadAdvice;

  std::vector<Vec3> f, trial(N), f_trial, d;
  const std::unique_ptr<NewtonLinearSolver> linear = newton_linear_solver(m, field);
  Shift shift;
  int64_t step = 0, cg_iterations = 0;
  double residual = INFINITY;
  StopReason reason = StopReason::StepLimit;
  for (int inc = 1; inc <= increments; ++inc) {
    model.pressure_pa = detail::increment_pressure(opt, inc, increments);
    const bool last = inc == increments;
    const double tol = opt.residual_tolerance * (last ? 1.0 : detail::Fire::kIntermediateToleranceFactor);
    field.evaluate(model, x, {}, f);
    detail::apply_holds(m, f);
    residual = mon.residual(f);
    mon.check_finite_forces(residual, step);
    double norm = std::sqrt(dot(f, f)), previous_norm = NAN;
    int64_t inverted = count_inverted(m, x);
    bool increment_done = residual < tol;
    while (!increment_done && step < opt.max_steps) {
      linear->linearize(model, x);
      const double eta = std::isfinite(previous_norm)
                             ? std::clamp(0.9 * (norm / previous_norm) * (norm / previous_norm), 1e-3, 0.1)
                             : 0.1;
      const CgOutcome cg = linear->solve(f, eta, opt.newton_max_cg_iterations, shift, d);
      cg_iterations += cg.iterations;

      // Backtracking on |f|: halve until it falls enough and no further tetrahedron inverts.
      double alpha = 1.0, trial_norm = INFINITY;
      int64_t trial_inverted = 0;
      bool accepted = false;
      for (int tries = 0; tries < 12; ++tries, alpha *= 0.5) {
        for (int64_t n = 0; n < N; ++n) trial[n] = x[n] + alpha * d[n];
        field.evaluate(model, trial, {}, f_trial);
        detail::apply_holds(m, f_trial);
        trial_norm = std::sqrt(dot(f_trial, f_trial));
        if (!(std::isfinite(trial_norm) && trial_norm <= (1.0 - 1e-4 * alpha) * norm)) continue;
        trial_inverted = count_inverted(m, trial);
        if ((accepted = trial_inverted <= inverted)) break;
      }
      if (!accepted) { reason = StopReason::NoDescent; break; }
      if (alpha == 1.0) shift.relax();
      x.swap(trial);
      f.swap(f_trial);
      previous_norm = norm;
      norm = trial_norm;
      inverted = trial_inverted;
      ++step;
      mon.check_diverged(x, step, advice);
      residual = mon.residual(f);
      if (mon.record(step, 0.0, model.pressure_pa, residual, x, {})) { reason = StopReason::InvertedTetrahedra; break; }
      increment_done = residual < tol;
    }
    if (reason == StopReason::InvertedTetrahedra || reason == StopReason::NoDescent) break;
    if (last && increment_done) reason = StopReason::Converged;
    if (!increment_done) break;
  }
  r.final_pressure_pa = model.pressure_pa;
  r.inner_iterations = cg_iterations;
  mon.finish(x, {}, step, field.evaluations(), reason, residual);
  return r;
}

}  // namespace pneumo
