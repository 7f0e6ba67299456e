// Newmark-β with Nimura's inner loop (method.md §6, Nimura §2.3.4): predictor
// x̃ = x + Δt v + (½ − β)Δt² a, ṽ = v + (1 − γ)Δt a; iterate a⁽ᵏ⁺¹⁾ = M⁻¹F(x̃ + βΔt² a⁽ᵏ⁾, ṽ + γΔt a⁽ᵏ⁾)
// until the change is below the tolerance, then commit. The loop is a fixed-point iteration: it
// converges only when ωΔt < 2(√(1+ξ²) − ξ) for every mode, no more stable than explicit.
#include <cmath>

#include "solve/force_field.h"
#include "solve/solver_common.h"

namespace pneumo {


namespace {
double max_norm(const std::vector<Vec3>& a) {
  double s = 0.0;
  for (const auto& v : a) s = std::max(s, v.norm());
  return s;
}
}  // namespace

SolveResult solve_newmark(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x) {
  SolveResult r;
  detail::Monitor mon(m, opt, "newmark", r);
  const double dt = detail::chosen_dt(m, opt, opt.forces.damping, r);
  const double beta = opt.newmark_beta, gamma = opt.newmark_gamma;
  const std::unique_ptr<ForceField> field = make_force_field(m, opt.forces);   // the springs (solve() admits no other)
  const int64_t N = m.node_count();
  std::vector<Vec3> v(N, Vec3::Zero()), a(N, Vec3::Zero()), a_next(N), xp(N), vp(N), xt(N), vt(N), f;
  // The inner loop's change is measured against the accelerations, floored by the acceleration the
  // reference load gives the heaviest node: near equilibrium the accelerations vanish and rounding
  // alone would otherwise look like a diverging loop.
  const double a_floor = detail::newmark_acceleration_floor(m, mon);
  ForceModel model = opt.forces;
  const std::string advice = detail::dt_advice(dt, r.dt_stable_s);
  int64_t step = 0;
  double residual = INFINITY;
  std::optional<StopReason> reason;   // none: go on
  while (step < opt.max_steps) {
    const double t_next = (step + 1) * dt;
    model.pressure_pa = detail::ramped_pressure(opt, t_next);
    for (int64_t n = 0; n < N; ++n) {
      xp[n] = x[n] + dt * v[n] + (0.5 - beta) * dt * dt * a[n];
      vp[n] = v[n] + (1.0 - gamma) * dt * a[n];
    }
    detail::NewmarkInnerLoop inner(opt.newmark_inner_tolerance, 0.0);
    for (int k = 0; k < opt.newmark_max_inner; ++k) {
      for (int64_t n = 0; n < N; ++n) {
        xt[n] = xp[n] + beta * dt * dt * a[n];
        vt[n] = vp[n] + gamma * dt * a[n];
      }
      field->evaluate(model, xt, vt, f);
      for (int64_t n = 0; n < N; ++n) a_next[n] = f[n] / m.mass_kg[n];
      detail::apply_holds(m, a_next);
      double change = 0.0;
      for (int64_t n = 0; n < N; ++n) change = std::max(change, (a_next[n] - a[n]).norm());
      a.swap(a_next);
      ++r.inner_iterations;
      if (inner.next(change, std::max(max_norm(a), a_floor))) break;
    }
    if (inner.failed())
      throw DivergedError(
          detail::newmark_failure(step + 1, inner, opt, dt, r.dt_stable_s),
          r.dt_stable_s);
    for (int64_t n = 0; n < N; ++n) {
      x[n] = xp[n] + beta * dt * dt * a[n];
      v[n] = vp[n] + gamma * dt * a[n];
    }
    detail::apply_holds(m, v);
    ++step;
    reason = mon.check_dynamic(step, t_next, model.pressure_pa, f, x, v, advice, &residual);
    if (reason) break;
  }
  r.final_pressure_pa = model.pressure_pa;
  mon.finish(x, v, step, field->evaluations(), reason.value_or(StopReason::StepLimit), residual);
  return r;
}

}  // namespace pneumo
