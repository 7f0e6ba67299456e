// Static equilibrium by FIRE (Bitzek et al., PRL 97, 170201, 2006; the FIRE 2.0 integration of
// Guénolé et al., Comput. Mater. Sci. 175, 109584, 2020), beyond the papers (method.md §6).
//
// Why FIRE: only the final shape matters for planning; FIRE is a force-only accelerated descent
// (≈√κ iterations where plain descent needs κ), it never climbs (it stops and restarts whenever the
// power F·v turns negative), and with fictitious masses m_i = Σ_j k_ij (Gershgorin: ω_max² ≤ 2)
// one set of parameters serves every mesh size, cube size and stiffness (any force field: the springs
// or the finite elements, force_field.h, each giving its own bound). Follower pressure is
// non-conservative, but FIRE needs no energy, only forces. The load is applied in increments of at
// most kMaxIncrementMmHg, each relaxed before the next, so large pressures do not invert
// tetrahedra on the way.
#include <cmath>

#include "solve/force_field.h"
#include "solve/solver_common.h"

namespace pneumo {

using F = detail::Fire;

SolveResult solve_static_fire(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x) {
  SolveResult r;
  detail::Monitor mon(m, opt, "static", r);
  const int64_t N = m.node_count();
  const std::unique_ptr<ForceField> field = make_force_field(m, opt.forces);
  const std::vector<double> mass = field->fire_masses(opt.forces);
  ForceModel model = opt.forces;
  model.damping = false;
  const int increments = detail::load_increments(opt);

  std::vector<Vec3> v(N, Vec3::Zero()), f;
  int64_t step = 0;
  double residual = INFINITY;
  StopReason reason = StopReason::StepLimit;
  const std::string advice = detail::kLoadAdvice;
  for (int inc = 1; inc <= increments && step < opt.max_steps; ++inc) {
    model.pressure_pa = detail::increment_pressure(opt, inc, increments);
    const bool last = inc == increments;
    const double tol = opt.residual_tolerance * (last ? 1.0 : F::kIntermediateToleranceFactor);
    detail::FireControl fire;
    std::fill(v.begin(), v.end(), Vec3::Zero());
    field->evaluate(model, x, {}, f);
    detail::apply_holds(m, f);
    bool increment_done = false;
    while (step < opt.max_steps) {
      double power = 0.0;
      for (int64_t n = 0; n < N; ++n) power += f[n].dot(v[n]);
      if (fire.after_power(power)) {
        for (int64_t n = 0; n < N; ++n) x[n] -= 0.5 * fire.dt * v[n];
        std::fill(v.begin(), v.end(), Vec3::Zero());
      }
      const double dt = fire.dt, alpha = fire.alpha;
      for (int64_t n = 0; n < N; ++n) v[n] += dt / mass[n] * f[n];
      if (power > 0.0) {
        double vnorm = 0.0, fnorm = 0.0;
        for (int64_t n = 0; n < N; ++n) { vnorm += v[n].squaredNorm(); fnorm += f[n].squaredNorm(); }
        vnorm = std::sqrt(vnorm);
        fnorm = std::sqrt(fnorm);
        if (fnorm > 0.0)
          for (int64_t n = 0; n < N; ++n) v[n] = (1.0 - alpha) * v[n] + alpha * vnorm / fnorm * f[n];
      }
      for (int64_t n = 0; n < N; ++n) x[n] += dt * v[n];
      field->evaluate(model, x, {}, f);
      detail::apply_holds(m, f);
      ++step;
      if (step % opt.monitor_every == 0 || step == opt.max_steps) {
        mon.check_diverged(x, step, advice);
        residual = mon.residual(f);
        if (mon.record(step, 0.0, model.pressure_pa, residual, x, {})) { reason = StopReason::InvertedTetrahedra; break; }
        if (residual < tol) { increment_done = true; break; }
      }
    }
    if (reason == StopReason::InvertedTetrahedra) break;
    if (last && increment_done) reason = StopReason::Converged;
    if (!increment_done) break;
  }
  r.final_pressure_pa = model.pressure_pa;
  mon.finish(x, {}, step, field->evaluations(), reason, residual);
  return r;
}

}  // namespace pneumo
