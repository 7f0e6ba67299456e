// The 2004 quasi-static scheme (method.md §6, Kitasaka §2.4): R_i ← R_i + Δs F_i / D_i, with D_i the
// sum of node i's spring stiffnesses (a Jacobi-scaled step: Δs is dimensionless and the paper's 0.3
// is meaningful). Forces: springs (no dampers), volume preservation, pressure; no mass. Nodes are
// updated one after another in index order (Gauss–Seidel), as the paper's sequential loop does
// (kitasaka_jacobi: all at once, as the device does, for comparing the two step by step);
// stop when Σ_i |ΔR_i| < β.
#include <cmath>

#include "solve/solver_common.h"

namespace pneumo {

namespace {

/// The force on node n alone from the current positions (springs, volume term, pressure).
Vec3 node_force(const Mesh& m, const Adjacency& adj, const ForceModel& model, const std::vector<Vec3>& x, int64_t n) {
  static const Vec3 kZero = Vec3::Zero();
  Vec3 f = Vec3::Zero();
  for (int64_t e = adj.springs.begin(n); e < adj.springs.end(n); ++e) {
    const int32_t s = adj.springs.item[e] / 8, slot = adj.springs.item[e] % 8;
    const int32_t a = m.springs[s][slot], b = m.springs[s][1 - slot];
    f += model.spring_model == SpringModel::Nonlinear
             ? spring_force_nonlinear(x[a], x[b], kZero, kZero, m.spring_rest_m[s], m.spring_k[s], 0.0, model.stiffening)
             : spring_force_linear(x[a], x[b], m.rest_m[a], m.rest_m[b], kZero, kZero, m.spring_k[s], 0.0);
  }
  if (model.volume_stiffness_pa != 0.0)
    for (int64_t e = adj.tets.begin(n); e < adj.tets.end(n); ++e) {
      const int32_t t = adj.tets.item[e] / 8, slot = adj.tets.item[e] % 8;
      const auto& q = m.tets[t];
      const double v0 = m.tet_rest_volume_m3[t];
      const double vol = signed_tet_volume(x[q[0]], x[q[1]], x[q[2]], x[q[3]]);
      f += -model.volume_stiffness_pa * m.tet_fraction[t] * (vol - v0) / v0 * tet_volume_gradient(x[q[0]], x[q[1]], x[q[2]], x[q[3]])[slot];
    }
  if (model.pressure_pa != 0.0)
    for (int64_t e = adj.loads.begin(n); e < adj.loads.end(n); ++e)
      f += pressure_load_forces(m, adj.loads.item[e] / 8, x, model.pressure_pa)[adj.loads.item[e] % 8];
  return f;
}

}  // namespace

SolveResult solve_kitasaka2004(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x) {
  SolveResult r;
  detail::Monitor mon(m, opt, "kitasaka2004", r);
  ForceEvaluator eval(m);   // for the residual, and the adjacency
  const Adjacency& adj = eval.adjacency();
  const int64_t N = m.node_count();
  const std::vector<double> stiffness = detail::stiffness_sums(m);
  ForceModel model = opt.forces;
  model.damping = false;
  std::vector<Vec3> f;
  int64_t step = 0;
  double residual = INFINITY, moved = INFINITY;
  StopReason reason = StopReason::StepLimit;
  const std::string advice = detail::kKitasakaAdvice;
  bool f_is_current = false;   // f holds the forces at x (the monitor just evaluated them)
  while (step < opt.max_steps) {
    moved = 0.0;
    // Jacobi: every node from the same positions' forces.
    if (opt.kitasaka_jacobi && !f_is_current) eval.evaluate(model, x, {}, f);
    f_is_current = false;
    for (int64_t n = 0; n < N; ++n) {
      if (m.hold[n] == kHoldAll || !(stiffness[n] > 0.0)) continue;
      Vec3 d = opt.kitasaka_step / stiffness[n] * (opt.kitasaka_jacobi ? f[n] : node_force(m, adj, model, x, n));
      for (int a = 0; a < 3; ++a)
        if (m.hold[n] & (1 << a)) d[a] = 0.0;
      x[n] += d;
      moved += d.norm();
    }
    ++step;
    const bool done = moved < opt.kitasaka_tolerance_m;
    if (done || step % opt.monitor_every == 0 || step == opt.max_steps) {
      mon.check_diverged(x, step, advice);
      eval.evaluate(model, x, {}, f);
      f_is_current = true;
      residual = mon.residual(f);
      if (mon.record(step, 0.0, model.pressure_pa, residual, x, {})) { reason = StopReason::InvertedTetrahedra; break; }
      if (done) { reason = StopReason::Converged; break; }
    }
  }
  r.final_pressure_pa = model.pressure_pa;
  // A Gauss-Seidel sweep evaluates every node's force once, outside `eval`: count it as one force evaluation.
  // Jacobi sweeps evaluate through `eval`, which counts them already.
  const int64_t sweeps_outside_eval = opt.kitasaka_jacobi ? 0 : step;
  mon.finish(x, {}, step, sweeps_outside_eval + eval.evaluations(), reason, residual);
  return r;
}

}  // namespace pneumo
