// Explicit integration, symplectic Euler (method.md §6): v ← v + Δt a; x ← x + Δt v.
#include <cmath>

#include "solve/force_field.h"
#include "solve/solver_common.h"

namespace pneumo {

SolveResult solve_explicit(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x) {
  SolveResult r;
  detail::Monitor mon(m, opt, "explicit", r);
  const double dt = detail::chosen_dt(m, opt, opt.forces.damping, r);
  const std::unique_ptr<ForceField> field = make_force_field(m, opt.forces);   // the springs (solve() admits no other)
  std::vector<Vec3> v(m.node_count(), Vec3::Zero()), f;
  ForceModel model = opt.forces;
  const std::string advice = detail::dt_advice(dt, r.dt_stable_s);
  int64_t step = 0;
  double residual = INFINITY;
  std::optional<StopReason> reason;   // none: go on
  while (step < opt.max_steps) {
    const double t = step * dt;
    model.pressure_pa = detail::ramped_pressure(opt, t);
    field->evaluate(model, x, v, f);
    for (int64_t n = 0; n < m.node_count(); ++n) v[n] += dt / m.mass_kg[n] * f[n];
    detail::apply_holds(m, v);
    for (int64_t n = 0; n < m.node_count(); ++n) x[n] += dt * v[n];
    ++step;
    reason = mon.check_dynamic(step, t + dt, model.pressure_pa, f, x, v, advice, &residual);
    if (reason) break;
  }
  r.final_pressure_pa = model.pressure_pa;
  mon.finish(x, v, step, field->evaluations(), reason.value_or(StopReason::StepLimit), residual);
  return r;
}

}  // namespace pneumo
