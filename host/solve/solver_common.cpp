#include "solve/solver_common.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/log.h"
#include "core/units.h"
#include "solve/solvable.h"

namespace pneumo::detail {

std::vector<double> fire_masses(const Mesh& m, const ForceModel& model) {
  std::vector<double> mass = stiffness_sums(m);
  if (model.volume_stiffness_pa != 0.0)
    for (std::size_t t = 0; t < m.tets.size(); ++t) {
      const auto& q = m.tets[t];
      const auto g = tet_volume_gradient(m.rest_m[q[0]], m.rest_m[q[1]], m.rest_m[q[2]], m.rest_m[q[3]]);
      for (int i = 0; i < 4; ++i)
        mass[q[i]] += std::abs(model.volume_stiffness_pa) * g[i].squaredNorm() / m.tet_rest_volume_m3[t];
    }
  for (auto& w : mass) w = w > 0.0 ? w : 1.0;
  return mass;
}

int load_increments(const SolveOptions& opt) {
  const double change_mmhg = (opt.forces.pressure_pa - opt.start_pressure_pa) / units::kPaPerMmHg;
  return std::max(1, int(std::ceil(std::abs(change_mmhg) / Fire::kMaxIncrementMmHg)));
}

double increment_pressure(const SolveOptions& opt, int increment, int increments) {
  return opt.start_pressure_pa + (opt.forces.pressure_pa - opt.start_pressure_pa) * double(increment) / increments;
}

double ramped_pressure(const SolveOptions& opt, double t_s) {
  return opt.start_pressure_pa +
         (opt.forces.pressure_pa - opt.start_pressure_pa) * ramp_factor(t_s, opt.ramp_s, opt.ramp_shape);
}

std::vector<double> stiffness_sums(const Mesh& m) {
  std::vector<double> d(m.node_count(), 0.0);
  for (std::size_t s = 0; s < m.springs.size(); ++s)
    for (int32_t n : m.springs[s]) d[n] += m.spring_k[s];
  return d;
}

double chosen_dt(const Mesh& m, const SolveOptions& opt, bool damping, SolveResult& r) {
  r.dt_stable_s = stable_time_step(m, damping);
  r.dt_s = opt.dt_s > 0.0 ? opt.dt_s : opt.dt_safety * r.dt_stable_s;
  return r.dt_s;
}

std::string dt_advice(double dt_s, double dt_stable_s) {
  std::ostringstream os;
  os.precision(3);
  os << "the time step " << dt_s / units::kSecondsPerMs << " ms is too large; set solver.dt_ms "
     << "below the largest stable step, about " << dt_stable_s / units::kSecondsPerMs << " ms (or 0 for automatic)";
  return os.str();
}

double newmark_acceleration_floor(const Mesh& m, const Monitor& mon) {
  double heaviest = 0.0;
  for (double mass : m.mass_kg) heaviest = std::max(heaviest, mass);
  return mon.reference_load() / heaviest;
}

std::string newmark_failure(int64_t step, const NewmarkInnerLoop& inner, const SolveOptions& opt, double dt_s,
                            double dt_stable_s) {
  std::ostringstream os;
  os.precision(3);
  os << "newmark inner loop did not converge at step " << step << " (relative change " << inner.relative_change()
     << " after " << inner.iterations() << " iterations, limit " << opt.newmark_inner_tolerance << "): ";
  if (inner.diverging())
    os << dt_advice(dt_s, dt_stable_s) << "; the loop converges only for ωΔt < 2(√(1+ξ²) − ξ), like explicit integration";
  else
    os << "it was still converging when solver.newmark_max_inner (" << opt.newmark_max_inner
       << ") ran out; raise it or solver.newmark_inner_tolerance, or set a smaller solver.dt_ms";
  return os.str();
}

void apply_holds(const Mesh& m, std::vector<Vec3>& vec) {
  for (int64_t n = 0; n < m.node_count(); ++n) {
    const uint8_t h = m.hold[n];
    if (!h) continue;
    for (int a = 0; a < 3; ++a)
      if (h & (1 << a)) vec[n][a] = 0.0;
  }
}

Monitor::Monitor(const Mesh& m, const SolveOptions& opt, const std::string& solver, SolveResult& r)
    : m_(m), opt_(opt), r_(r), start_(std::chrono::steady_clock::now()), progress_("solve " + solver, 0) {
  r.solver = solver;
  check_solvable(m, opt);   // nothing free, or a part the load would carry away: no solver can answer
  // Reference load: the largest nodal force of the pressure and gravity at rest (gravity alone when
  // the unloaded shape is sought, gravity_compensation.h).
  std::vector<Vec3> f = pressure_forces(m, m.rest_m, opt.forces.pressure_pa);
  if (!m.mass_kg.empty())
    for (int64_t n = 0; n < m.node_count(); ++n) f[n] += m.mass_kg[n] * opt.forces.gravity_m_s2;
  double ref = 0.0;
  for (const auto& v : f) ref = std::max(ref, v.norm());
  if (!(ref > 0.0)) {
    for (std::size_t s = 0; s < m.springs.size(); ++s) ref = std::max(ref, 1e-3 * m.spring_k[s] * m.spring_rest_m[s]);
  }
  ref_load_ = ref > 0.0 ? ref : 1.0;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const auto& x : m.rest_m) { lo = lo.cwiseMin(x); hi = hi.cwiseMax(x); }
  extent_m_ = std::max((hi - lo).norm(), 1e-3);
}

// The three maxima below are infinite as soon as one term is not finite: std::max(m, NaN) keeps m,
// so a plain running maximum would pass over a NaN force or position and call the run converged.
double Monitor::residual(const std::vector<Vec3>& f) const {
  double worst = 0.0;
  for (int64_t n = 0; n < m_.node_count(); ++n)
    for (int a = 0; a < 3; ++a)
      if (!(m_.hold[n] & (1 << a))) {
        const double c = std::abs(f[n][a]);
        if (!std::isfinite(c)) return INFINITY;
        worst = std::max(worst, c);
      }
  return worst / ref_load_;
}

double Monitor::max_speed(const std::vector<Vec3>& v) const {
  double s = 0.0;
  for (const auto& x : v) {
    const double c = x.norm();
    if (!std::isfinite(c)) return INFINITY;
    s = std::max(s, c);
  }
  return s;
}

double Monitor::max_displacement(const std::vector<Vec3>& x) const {
  double d = 0.0;
  for (int64_t n = 0; n < m_.node_count(); ++n) {
    const double c = (x[n] - m_.rest_m[n]).norm();
    if (!std::isfinite(c)) return INFINITY;
    d = std::max(d, c);
  }
  return d;
}

void Monitor::check_diverged(const std::vector<Vec3>& x, int64_t step, const std::string& advice) const {
  check_diverged(max_displacement(x), step, advice);
}

void Monitor::check_diverged(double max_displacement_m, int64_t step, const std::string& advice) const {
  // A non-finite position makes max_displacement_m NaN or infinite: both fail the test below.
  if (max_displacement_m <= extent_m_) return;
  // A dynamic scheme within its stable step did not blow up by Δt: do not tell the user to shrink it.
  const bool dt_is_stable = r_.dt_s > 0.0 && r_.dt_s <= r_.dt_stable_s;
  // Undamped, a dynamic scheme overshoots the equilibrium by as much again and never settles; with
  // nonlinear springs the swing grows until the wall leaves the model: the damping is to blame.
  const bool undamped = r_.dt_s > 0.0 && (!opt_.forces.damping || std::all_of(m_.spring_c.begin(), m_.spring_c.end(),
                                                                               [](double c) { return c == 0.0; }));
  std::ostringstream os;
  os.precision(3);
  os << r_.solver << " diverged at step " << step << " (";
  if (std::isfinite(max_displacement_m))
    os << "a node moved " << units::m_to_mm(max_displacement_m) << " mm, beyond the model's size";
  else
    os << "non-finite positions";
  os << "): ";
  if (dt_is_stable && undamped)
    os << "nothing damps the motion (material.damping_ratio is 0), so the wall's swing around its equilibrium grows "
          "until it leaves the model; set material.damping_ratio above 0 (Nimura: 0.4) or use solver.method "
          "\"static\", which needs no damping";
  else
    os << (dt_is_stable ? std::string(kLoadAdvice) + " (the time step is within its stable estimate)" : advice);
  throw DivergedError(os.str(), r_.dt_stable_s);
}

SolverEta solver_eta(const std::vector<SolveSample>& history, double tolerance, int64_t max_steps,
                     double seconds_per_step, double start_pressure_pa, double final_pressure_pa) {
  SolverEta out;
  if (history.empty()) return out;
  const SolveSample& now = history.back();
  const double budget_s = double(std::max<int64_t>(max_steps - now.step, 0)) * seconds_per_step;
  // Still raising the load (a static scheme's increments, a dynamic scheme's ramp): the residual of
  // this load says nothing of the loads to come, and right after an increment it jumps by orders of
  // magnitude, which read as "never converges" once showed "ETA ~35h" to a 30 s solve. The load still
  // to apply is estimated to take as long per unit of load as the load applied so far has.
  const double span = final_pressure_pa - start_pressure_pa;
  const double applied = span != 0.0 ? (now.pressure_pa - start_pressure_pa) / span : 1.0;
  if (applied < 1.0 - 1e-9) {
    if (applied > 0.0) out.seconds = std::min(double(now.step) * seconds_per_step * (1.0 - applied) / applied, budget_s);
    return out;
  }
  if (!(now.residual > tolerance)) return out;   // there: no estimate needed
  // The slower of the decay rates over the last 5 and the last 20 monitoring samples at this load: an
  // oscillating residual dips for a few samples at a time, and a dip alone once promised "~0.1 s" to
  // a run that never converged.
  std::size_t at_this_load = 0;
  while (at_this_load < history.size() && history[history.size() - 1 - at_this_load].pressure_pa == now.pressure_pa)
    ++at_this_load;
  if (at_this_load < 5) return out;
  double rate = -INFINITY;
  for (std::size_t back : {std::size_t(4), std::size_t(19)}) {
    if (back >= at_this_load) continue;
    const SolveSample& old = history[history.size() - 1 - back];
    if (now.step <= old.step || !(old.residual > 0.0)) continue;
    rate = std::max(rate, (std::log(now.residual) - std::log(old.residual)) / double(now.step - old.step));
  }
  if (rate < 0.0 && std::isfinite(rate)) out.seconds = (std::log(tolerance) - std::log(now.residual)) / rate * seconds_per_step;
  // Never past the step budget: the run ends there whatever the residual does.
  if (out.seconds < 0.0 || out.seconds > budget_s) {
    out.seconds = budget_s;
    out.step_limit = true;
  }
  return out;
}

bool Monitor::record(int64_t step, double time_s, double pressure_pa, double residual, const std::vector<Vec3>& x,
                     const std::vector<Vec3>& v) {
  return record(step, time_s, pressure_pa, residual, max_displacement(x), v.empty() ? 0.0 : max_speed(v),
                [&]() -> const std::vector<Vec3>& { return x; });
}

void Monitor::check_finite_forces(double residual, int64_t step) const {
  // A NaN or infinite force (residual() makes any non-finite term infinite) ends every scheme,
  // whether or not it has reached the positions yet: a line search would only call it "no descent".
  if (std::isfinite(residual)) return;
  std::ostringstream os;
  os << r_.solver << " diverged at step " << step
     << " (non-finite forces): a material value that makes them overflow or vanish (material.young_kpa and its "
        "overrides, spring_scale, density_kg_m3) or the load; check them. With the finite elements (material.model "
        "fem-*), the static and explicit schemes can diverge where solver.method \"newton\" converges";
  throw DivergedError(os.str(), r_.dt_stable_s);
}

bool Monitor::record(int64_t step, double time_s, double pressure_pa, double residual, double max_displacement_m,
                     double max_speed_m_s, const std::function<const std::vector<Vec3>&()>& positions) {
  check_finite_forces(residual, step);
  SolveSample s;
  s.step = step;
  s.time_s = time_s;
  s.pressure_pa = pressure_pa;
  s.residual = residual;
  s.max_displacement_m = max_displacement_m;
  s.max_speed_m_s = max_speed_m_s;
  r_.history.push_back(s);
  char detail[160];
  std::snprintf(detail, sizeof detail, "residual %.2e (target %.0e)  P %.1f mmHg  max displacement %.1f mm",
                residual, opt_.residual_tolerance, pressure_pa / units::kPaPerMmHg,
                units::m_to_mm(s.max_displacement_m));
  const double seconds_per_step =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count() / double(std::max<int64_t>(step, 1));
  const SolverEta eta = solver_eta(r_.history, opt_.residual_tolerance, opt_.max_steps, seconds_per_step,
                                   opt_.start_pressure_pa, opt_.forces.pressure_pa);
  std::string shown = detail;
  // During a dynamic scheme's ramp the residual grows with the load: no cause for a warning yet. The
  // static schemes (time 0, no time step) step their load in increments instead.
  const bool ramping = r_.dt_s > 0.0 && time_s < opt_.ramp_s;
  if (eta.step_limit && !ramping) shown += "  (at this rate the run ends at solver.max_steps)";
  if (opt_.progress) progress_.update(step, shown, eta.seconds);
  if (opt_.on_snapshot && opt_.snapshot_every_steps > 0 && step >= next_snapshot_) {
    opt_.on_snapshot(SolverSnapshot{step, time_s, pressure_pa, positions()});
    next_snapshot_ = (step / opt_.snapshot_every_steps + 1) * opt_.snapshot_every_steps;
  }
  if (opt_.on_inverted == OnInverted::Stop) {
    r_.inverted_tetrahedra = count_inverted(m_, positions());
    return r_.inverted_tetrahedra > 0;
  }
  return false;
}

std::optional<StopReason> Monitor::check_dynamic(int64_t step, double time_s, double pressure_pa, const std::vector<Vec3>& f,
                                   const std::vector<Vec3>& x, const std::vector<Vec3>& v, const std::string& advice,
                                   double* residual) {
  if (step % opt_.monitor_every != 0 && step != opt_.max_steps) return std::nullopt;
  return check_dynamic(step, time_s, pressure_pa, this->residual(f), max_displacement(x), max_speed(v), advice,
                       [&]() -> const std::vector<Vec3>& { return x; }, residual);
}

std::optional<StopReason> Monitor::check_dynamic(int64_t step, double time_s, double pressure_pa, double residual_now,
                                   double max_displacement_m, double max_speed_m_s, const std::string& advice,
                                   const std::function<const std::vector<Vec3>&()>& positions, double* residual) {
  check_diverged(max_displacement_m, step, advice);
  *residual = residual_now;
  if (record(step, time_s, pressure_pa, residual_now, max_displacement_m, max_speed_m_s, positions))
    return StopReason::InvertedTetrahedra;
  const bool ramped = time_s >= opt_.ramp_s;
  const bool still = ramped && residual_now < opt_.residual_tolerance && max_speed_m_s < opt_.velocity_tolerance_m_s;
  held_steps_ = still ? held_steps_ + opt_.monitor_every : 0;
  if (held_steps_ >= opt_.hold_steps) return StopReason::Converged;
  return std::nullopt;
}

void Monitor::finish(const std::vector<Vec3>& x, const std::vector<Vec3>& v, int64_t steps, int64_t force_evaluations,
                     StopReason stop_reason, double residual) {
  // Whatever the scheme checked on the way, no result with a non-finite position leaves a solver.
  // (A finite one beyond the model's size was the schemes' to catch, with their own advice.)
  if (const double d = max_displacement(x); !std::isfinite(d)) check_diverged(d, steps, std::string(kLoadAdvice));
  r_.x = x;
  r_.v = v.empty() ? std::vector<Vec3>(x.size(), Vec3::Zero()) : v;
  r_.steps = steps;
  r_.force_evaluations = force_evaluations;
  r_.converged = stop_reason == StopReason::Converged;
  r_.stop_reason = stop_reason;
  r_.residual = residual;
  r_.inverted_tetrahedra = count_inverted(m_, x);
  if (r_.inverted_tetrahedra > 0 && opt_.on_inverted == OnInverted::Continue)
    log::warn(r_.solver + ": " + std::to_string(r_.inverted_tetrahedra) + " of " + std::to_string(m_.tets.size()) +
              " tetrahedra are inverted at the end (the load turned them inside out: the result is not physical "
              "there); solver.on_inverted = \"stop\" stops at the first, a stiffer material or a lower pressure "
              "avoids them");
  r_.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  char detail[160];
  std::snprintf(detail, sizeof detail, "%s after %lld steps, residual %.2e", stop_reason_text(stop_reason), (long long)steps,
                residual);
  if (opt_.progress) progress_.finish(detail);
}

}  // namespace pneumo::detail
