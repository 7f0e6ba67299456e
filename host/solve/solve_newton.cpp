// Static equilibrium by Newton's method with matrix-free preconditioned conjugate gradients, on any
// force field (force_field.h): the springs or the finite elements (docs/fem.md).
//
// Each Newton iteration solves K d = f(x) for the step d (newton_linear_solver.h: on the host, or on
// the OpenCL device that holds the force field), with K = −∂f/∂x the stiffness at x (the
// force field's elastic part and the gas pressure's, pressure_stiffness.h), by CG preconditioned with
// the inverse 3×3 diagonal blocks of K (block Jacobi), to a relative residual η chosen as Eisenstat &
// Walker (1996, choice 2: η = 0.9 (|f_k|/|f_{k−1}|)², within [10⁻³, 0.1]), so early iterations are
// cheap and late ones converge fast. A backtracking line search halves the step until the total
// potential energy Π = E − W falls (Armijo, 10⁻⁴; E the field's elastic energy, W the loads' work
// along the step), Π is not rising steeply there (strong Wolfe's upper side, 0.9) and no further
// tetrahedron inverts; |f| is only the convergence test. Where no step passes, the
// Levenberg–Marquardt shift grows and the step is solved again. The load is
// applied in the static solver's increments, each solved before the next.
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
#include <vector>

#include "core/log.h"
#include "solve/conjugate_gradients.h"
#include "solve/force_field.h"
#include "solve/newton_linear_solver.h"
#include "solve/solver_common.h"

namespace pneumo {

namespace {

// The work the loads do along the straight path x + s d, s ∈ [0, α]: gravity's (constant) exactly, and
// the gas pressure's by Simpson's rule, which is exact here: each load's f_i = −P cof(D_s) c_i is
// quadratic in s along a straight path (cof of a matrix linear in s), so f·d is too. The work, unlike
// P·ΔV, needs no closed cavity surface.
double load_work(const Mesh& m, const ForceModel& model, const std::vector<Vec3>& x, const std::vector<Vec3>& d,
                 double alpha) {
  double w = 0.0;
  if (model.gravity_m_s2 != Vec3::Zero() && !m.mass_kg.empty())
    for (int64_t n = 0; n < m.node_count(); ++n) w += alpha * m.mass_kg[n] * model.gravity_m_s2.dot(d[n]);
  if (model.pressure_pa == 0.0) return w;
  const int64_t R = int64_t(m.load_tet.size());
  // Each load's work on its own, summed after in the loads' order: a parallel reduction would add in
  // an order that follows the thread count, and the line search's decisions with it.
  std::vector<double> work(std::size_t(R), 0.0);
#pragma omp parallel for schedule(static) if (R > 20000)
  for (int64_t l = 0; l < R; ++l) {
    const auto& q = m.tets[m.load_tet[l]];
    double simpson = 0.0;
    for (int k = 0; k <= 2; ++k) {
      const double s = 0.5 * alpha * k;
      std::array<Vec3, 4> y;
      for (int i = 0; i < 4; ++i) y[i] = x[q[i]] + s * d[q[i]];
      const Vec3 e1 = y[1] - y[0], e2 = y[2] - y[0], e3 = y[3] - y[0];
      double fd = 0.0;
      for (int i = 0; i < 4; ++i) fd -= model.pressure_pa * cofactor_times(e1, e2, e3, m.load_c[l][i]).dot(d[q[i]]);
      simpson += (k == 1 ? 4.0 : 1.0) * fd;
    }
    work[std::size_t(l)] = alpha / 6.0 * simpson;
  }
  double wp = 0.0;
  for (const double v : work) wp += v;
  return w + wp;
}

// The line search's constants: Armijo's sufficient decrease c₁ and the curvature condition's c₂ (N&W's
// values for Newton directions), the backtracks before σ grows, and the
// relative change of Π below which double rounding of the energy (a sum over every tetrahedron) hides it.
constexpr double kArmijo = 1e-4, kCurvature = 0.9, kEnergyRounding = 1e-11;
constexpr int kBacktracks = 12;

// Why a line search found no step, and what to change. Π falling only where tetrahedra turn inside out
// is a load the material does not hold within the mesh: a law without a barrier at J → 0 (co-rotational,
// springs) lets elements collapse, and an equilibrium, if any, lies past them.
const char* const kInversionAdvice =
    "newton: every step that lowers the energy turns a tetrahedron inside out: the tissue collapses under "
    "this load; lower load.pressure_mmhg, raise material.young_kpa (or material.fat_young_kpa), refine "
    "mesh.cube_voxels, or use \"fem-neohookean\" with material.stiffening > 0";
const char* const kNoDescentAdvice =
    "newton: no step lowers the energy, even along scaled steepest descent (the forces are not the energy's "
    "gradient to rounding); raise solver.residual_tolerance";

}  // namespace

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
    double energy = field.elastic_energy(model, x);
    bool increment_done = residual < tol;
    while (!increment_done && step < opt.max_steps) {
      linear->linearize(model, x);
      const double eta = std::isfinite(previous_norm)
                             ? std::clamp(0.9 * (norm / previous_norm) * (norm / previous_norm), 1e-3, 0.1)
                             : 0.1;
      // Backtracking on the total potential energy Π = E − W (Armijo, Nocedal & Wright §3.1, §6.2): halve
      // α until Π(x + αd) − Π(x) ≤ −c₁ α f·d, Π is not rising steeply at α (below) and no further
      // tetrahedron inverts. f·d > 0 for any
      // conjugate-gradient iterate of a positive definite K + σD, so d descends Π, where it need not
      // descend |f|: away from the solution a Newton step that lowers the energy often raises |f|
      // (on the co-rotational real CT |f| allowed α = 1/16 where Π allowed 1/2, until no α lowered |f|).
      // Where no α is accepted, σ grows tenfold and d is solved again: the Levenberg–Marquardt path
      // turns d towards scaled steepest descent, along which a short enough step always lowers Π.
      double alpha = 1.0, trial_norm = INFINITY, trial_energy = NAN;
      int64_t trial_inverted = 0;
      bool accepted = false, blocked_by_inversion = false;
      for (;;) {
        const CgOutcome cg = linear->solve(f, eta, opt.newton_max_cg_iterations, shift, d);
        cg_iterations += cg.iterations;
        const double slope = dot(f, d);   // −Π'(0) along d
        alpha = 1.0;
        for (int tries = 0; tries < kBacktracks && slope > 0.0; ++tries, alpha *= 0.5) {
          for (int64_t n = 0; n < N; ++n) trial[n] = x[n] + alpha * d[n];
          field.evaluate(model, trial, {}, f_trial);
          detail::apply_holds(m, f_trial);
          trial_norm = std::sqrt(dot(f_trial, f_trial));
          trial_energy = field.elastic_energy(model, trial);
          const double change = trial_energy - energy - load_work(m, model, x, d, alpha);
          const double trial_slope = dot(f_trial, d);   // −Π'(α)
          if (std::isfinite(trial_norm) && std::isfinite(change)) {
            // Near the solution the change in Π is below the rounding of Π itself; there |f| decides.
            const bool in_rounding = std::abs(change) <= kEnergyRounding * std::abs(energy);
            const bool decreases = in_rounding ? trial_norm <= (1.0 - kArmijo * alpha) * norm
                                               : change <= -kArmijo * alpha * slope;
            // The curvature condition's upper side (strong Wolfe, N&W (3.7b)): Π must not be rising
            // steeply at α. Without it a full step from rest into Demiray's exponential regime lowers Π
            // yet overshoots the minimum along d by orders of magnitude in |f|, which the next
            // iterations then walk back.
            const bool not_overshot = -trial_slope <= kCurvature * slope;
            if (decreases && not_overshot) {
              trial_inverted = count_inverted(m, trial);
              if ((accepted = trial_inverted <= inverted)) break;
              blocked_by_inversion = true;
            }
          }
        }
        if (accepted || shift.sigma >= Shift::kMax) break;
        shift.sigma = std::max(10.0 * shift.sigma, Shift::kFirst);
      }
      if (!accepted) {
        reason = StopReason::NoDescent;
        log::warn(blocked_by_inversion ? kInversionAdvice : kNoDescentAdvice);
        break;
      }
      if (alpha == 1.0) shift.relax();
      x.swap(trial);
      f.swap(f_trial);
      previous_norm = norm;
      norm = trial_norm;
      energy = trial_energy;
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
