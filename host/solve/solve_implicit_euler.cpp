// Dynamics by backward (implicit) Euler with conjugate gradients, on any force field: Bano 2012's scheme
// (SOFA's EulerImplicitSolver, after Baraff & Witkin 1998), one linearised solve per time step h:
//   ((1 + hα) M + h(h + β) K) Δv = h (f(x_n) − (h + β) K v_n − α M v_n),   v ← v + Δv,   x ← x + h v,
// with K = −∂f/∂x at x_n (the field's and the gas pressure's, as Newton's, pressure_stiffness.h) and
// Rayleigh's damping C = α M + β K (solver.rayleigh_mass_per_s, solver.rayleigh_stiffness_s; SOFA's
// former defaults 0.1 and 0.1). The springs' own dampers are left out: C is the damping here, for
// every model alike. For a positive K the matrix is positive definite at any h, so the scheme is
// stable at any step (it damps what it cannot resolve); h sets how closely it follows the ramp:
// solver.dt_ms, or 0 for the ramp in 50 steps. CG is preconditioned by the blocks
// (1 + hα) m_i I + h(h + β) K_ii and solved to 10⁻⁴; where K is indefinite the matrix takes the shift
// Newton uses (conjugate_gradients.h).
#include <cmath>
#include <sstream>

#include "core/units.h"
#include "solve/conjugate_gradients.h"
#include "solve/force_field.h"
#include "solve/pressure_stiffness.h"
#include "solve/solver_common.h"

namespace pneumo {

namespace {
constexpr double kCgTolerance = 1e-4;
constexpr int kRampSteps = 50;
}  // namespace

SolveResult solve_implicit_euler(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x) {
  SolveResult r;
  detail::Monitor mon(m, opt, "implicit-euler", r);
  const int64_t N = m.node_count();
  r.dt_stable_s = stable_time_step(m, false);   // the explicit schemes' bound, for comparison only
  const double h = opt.dt_s > 0.0 ? opt.dt_s : opt.ramp_s > 0.0 ? opt.ramp_s / kRampSteps : 10.0 * r.dt_stable_s;
  r.dt_s = h;
  const double alpha = opt.rayleigh_mass_per_s, beta = opt.rayleigh_stiffness_s;
  const std::unique_ptr<ForceField> field = make_force_field(m, opt.forces);
  ForceModel model = opt.forces;
  model.damping = false;
  PressureStiffness pressure;
  std::ostringstream advice_text;
  advice_text.precision(3);
  advice_text << "implicit Euler diverged at the time step " << h / units::kSecondsPerMs
              << " ms; lower solver.dt_ms or raise solver.rayleigh_mass_per_s";
  const std::string advice = advice_text.str();

  std::vector<Vec3> v(N, Vec3::Zero()), f, kv, b(N), dv;
  std::vector<Mat3> blocks, a_blocks(N);
  int64_t step = 0, cg_iterations = 0;
  double residual = INFINITY;
  Shift shift;
  std::optional<StopReason> reason;   // none: go on
  const double k_scale = h * (h + beta);
  while (step < opt.max_steps) {
    const double t = step * h;
    model.pressure_pa = detail::ramped_pressure(opt, t + h);
    field->evaluate(model, x, {}, f);
    field->linearize(model, x);
    pressure.linearize(m, x, model.pressure_pa);
    field->stiffness_diagonal(blocks);
    for (int64_t n = 0; n < N; ++n) a_blocks[n] = (1.0 + h * alpha) * m.mass_kg[n] * Mat3::Identity() + k_scale * blocks[n];
    const std::vector<Mat3> precond = block_jacobi(m, a_blocks);
    field->stiffness_product(v, kv);
    pressure.add_product(v, kv);
    for (int64_t n = 0; n < N; ++n) b[n] = h * (f[n] - (h + beta) * kv[n] - alpha * m.mass_kg[n] * v[n]);
    detail::apply_holds(m, b);
    const LinearOperator A = [&](const std::vector<Vec3>& p, std::vector<Vec3>& ap) {
      field->stiffness_product(p, ap);
      pressure.add_product(p, ap);
      for (int64_t n = 0; n < N; ++n) ap[n] = (1.0 + h * alpha) * m.mass_kg[n] * p[n] + k_scale * ap[n];
    };
    const CgOutcome cg =
        shifted_conjugate_gradients(m, A, a_blocks, precond, b, kCgTolerance, opt.newton_max_cg_iterations, shift, dv);
    cg_iterations += cg.iterations;
    if (!cg.negative_curvature) shift.relax();
    for (int64_t n = 0; n < N; ++n) v[n] += dv[n];
    detail::apply_holds(m, v);
    for (int64_t n = 0; n < N; ++n) x[n] += h * v[n];
    ++step;
    reason = mon.check_dynamic(step, t + h, model.pressure_pa, f, x, v, advice, &residual);
    if (reason) break;
  }
  r.final_pressure_pa = model.pressure_pa;
  r.inner_iterations = cg_iterations;
  mon.finish(x, v, step, field->evaluations(), reason.value_or(StopReason::StepLimit), residual);
  return r;
}

}  // namespace pneumo
