// Static equilibrium by FIRE (Bitzek et al., PRL 97, 170201, 2006; the FIRE 2.0 integration of
// Guénolé et al., Comput. Mater. Sci. 175, 109584, 2020), beyond the papers (method.md §6).
//
// Why FIRE: only the final shape matters for planning; FIRE is a force-only accelerated descent
// (≈√κ iterations where plain descent needs κ), it never climbs (it stops and restarts whenever the
// power F·v turns negative), and with fictitious masses m_i = Σ_j k_ij (Gershgorin: ω_max² ≤ 2)
// one set of parameters serves every mesh size, cube size and stiffness. Follower pressure is
// non-conservative, but FIRE needs no energy, only forces. The load is applied in increments of at
// most kMaxIncrementMmHg, each relaxed before the next, so large pressures do not invert
// tetrahedra on the way.
#include <cmath>

#include "core/units.h"
#include "solve/solver_common.h"

namespace pneumo {

namespace {
constexpr double kMaxIncrementMmHg = 4.0;
// FIRE parameters (Bitzek 2006 / Guénolé 2020 defaults), in pseudo-time units where ω_max ≤ √2.
constexpr double kDtMax = 1.0, kDtStart = 0.1, kDtMin = 0.02;
constexpr int kDelaySteps = 5;
constexpr double kGrow = 1.1, kShrink = 0.5, kAlphaStart = 0.1, kAlphaShrink = 0.99;
// Intermediate load increments need only a rough equilibrium.
constexpr double kIntermediateToleranceFactor = 10.0;
}  // namespace

SolveResult solve_static_fire(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x) {
  SolveResult r;
  detail::Monitor mon(m, opt, "static", r);
  const int64_t N = m.node_count();
  // Fictitious masses: the node's spring stiffness sum (plus the volume term's, when on).
  std::vector<double> mass(N, 0.0);
  for (std::size_t s = 0; s < m.springs.size(); ++s)
    for (int32_t n : m.springs[s]) mass[n] += m.spring_k[s];
  if (opt.forces.volume_stiffness_pa != 0.0)
    for (std::size_t t = 0; t < m.tets.size(); ++t) {
      const auto& q = m.tets[t];
      const auto g = tet_volume_gradient(m.rest_m[q[0]], m.rest_m[q[1]], m.rest_m[q[2]], m.rest_m[q[3]]);
      for (int i = 0; i < 4; ++i)
        mass[q[i]] += std::abs(opt.forces.volume_stiffness_pa) * g[i].squaredNorm() / m.tet_rest_volume_m3[t];
    }
  for (auto& w : mass) w = w > 0.0 ? w : 1.0;

  ForceEvaluator eval(m);
  ForceModel model = opt.forces;
  model.damping = false;
  const double target_mmhg = opt.forces.pressure_pa / units::kPaPerMmHg;
  const int increments = std::max(1, int(std::ceil(std::abs(target_mmhg) / kMaxIncrementMmHg)));

  std::vector<Vec3> v(N, Vec3::Zero()), f;
  int64_t step = 0;
  double residual = INFINITY;
  bool converged = false;
  std::string reason = "step limit";
  const std::string advice = "the static solver failed to relax this load; check for unattached parts (no fixed nodes)";
  for (int inc = 1; inc <= increments && step < opt.max_steps; ++inc) {
    model.pressure_pa = opt.forces.pressure_pa * double(inc) / increments;
    const bool last = inc == increments;
    const double tol = opt.residual_tolerance * (last ? 1.0 : kIntermediateToleranceFactor);
    double dt = kDtStart, alpha = kAlphaStart;
    int positive = 0;
    std::fill(v.begin(), v.end(), Vec3::Zero());
    eval.evaluate(model, x, {}, f);
    detail::apply_holds(m, f);
    bool increment_done = false;
    while (step < opt.max_steps) {
      double power = 0.0;
      for (int64_t n = 0; n < N; ++n) power += f[n].dot(v[n]);
      if (power > 0.0) {
        if (++positive > kDelaySteps) {
          dt = std::min(dt * kGrow, kDtMax);
          alpha *= kAlphaShrink;
        }
      } else {
        positive = 0;
        dt = std::max(dt * kShrink, kDtMin);
        alpha = kAlphaStart;
        for (int64_t n = 0; n < N; ++n) x[n] -= 0.5 * dt * v[n];
        std::fill(v.begin(), v.end(), Vec3::Zero());
      }
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
      eval.evaluate(model, x, {}, f);
      detail::apply_holds(m, f);
      ++step;
      if (step % opt.monitor_every == 0 || step == opt.max_steps) {
        mon.check_diverged(x, step, advice);
        residual = mon.residual(f);
        if (mon.record(step, 0.0, model.pressure_pa, residual, x, {})) { reason = "inverted tetrahedra"; break; }
        if (residual < tol) { increment_done = true; break; }
      }
    }
    if (reason == "inverted tetrahedra") break;
    if (last && increment_done) { converged = true; reason = "converged"; }
    if (!increment_done) break;
  }
  r.final_pressure_pa = model.pressure_pa;
  mon.finish(x, {}, step, eval.evaluations(), converged, reason, residual);
  return r;
}

}  // namespace pneumo
