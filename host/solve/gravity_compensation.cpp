#include "solve/gravity_compensation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "core/log.h"
#include "core/stopwatch.h"
#include "core/units.h"

namespace pneumo {

namespace {

constexpr double kSagFraction = 1e-2;   // stop when x(X*) is within 1 % of the sag of x_CT
constexpr int kMaxSteps = 10;

/// The largest |a − b| over the nodes (metres).
double largest_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0.0;
  for (std::size_t n = 0; n < a.size(); ++n) d = std::max(d, (a[n] - b[n]).norm());
  return d;
}

std::string mm(double metres) {
  char s[32];
  std::snprintf(s, sizeof s, "%.3g mm", units::m_to_mm(metres));
  return s;
}

}  // namespace

UnloadedShape unloaded_shape(const Mesh& ct, const SolveOptions& opt, const StaticSolveFn& solve) {
  if (!(opt.forces.gravity_m_s2.squaredNorm() > 0.0))
    throw std::invalid_argument("unloaded_shape: gravity is off, nothing to compensate");
  const auto t0 = std::chrono::steady_clock::now();
  SolveOptions g = opt;
  g.forces.pressure_pa = 0.0;
  g.start_pressure_pa = 0.0;
  g.snapshot_every_steps = 0;
  g.on_snapshot = nullptr;
  g.forces.tie_interface = true;   // no gas yet: the wall lies on the viscera (interface_tie.h)
  if (g.method != SolverMethod::Newton) g.method = SolverMethod::Static;   // the static solvers of force fields

  const std::vector<Vec3>& x_ct = ct.rest_m;
  UnloadedShape u;
  u.mesh = ct;
  std::vector<Vec3> rest = x_ct;
  double previous_error = INFINITY;
  for (int k = 0; k < kMaxSteps; ++k) {
    const SolveResult r = solve(u.mesh, g, x_ct);
    ++u.iterations;
    u.solver_steps += r.steps;
    if (!r.converged)
      throw std::runtime_error("gravity compensation: the solve under gravity alone stopped (" + std::string(stop_reason_text(r.stop_reason)) +
                               ", residual " + std::to_string(r.residual) +
                               "): the body does not carry its own weight; check the fixed roles "
                               "(roles.fixed_labels), raise material.young_kpa, or set material.gravity_compensation "
                               "to false");
    const double error = largest_difference(r.x, x_ct);
    if (k == 0) u.sag_mm = units::m_to_mm(error);
    u.error_mm = units::m_to_mm(error);
    log::info("gravity compensation, step " + std::to_string(k + 1) + ": the CT shape is missed by " + mm(error) +
              " (sag " + mm(units::kMetresPerMm * u.sag_mm) + ")");
    if (error <= kSagFraction * units::kMetresPerMm * u.sag_mm) {
      u.wall_time_s = seconds_since(t0);
      return u;
    }
    if (!(error < previous_error))
      throw std::runtime_error("gravity compensation does not converge: step " + std::to_string(k + 1) +
                               " misses the CT shape by " + mm(error) + ", the step before by " + mm(previous_error) +
                               " (sag " + mm(units::kMetresPerMm * u.sag_mm) +
                               "): the tissue is too soft for its weight; raise material.young_kpa (or "
                               "fat_young_kpa), or set material.gravity_compensation to false");
    previous_error = error;
    for (std::size_t n = 0; n < rest.size(); ++n) rest[n] += x_ct[n] - r.x[n];
    try {
      u.mesh = with_rest_shape(ct, rest);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(std::string("gravity compensation: ") + e.what() +
                               ": the unloaded shape folds over; raise material.young_kpa or set "
                               "material.gravity_compensation to false");
    }
  }
  throw std::runtime_error("gravity compensation: " + std::to_string(kMaxSteps) + " steps leave the CT shape missed by " +
                           mm(units::kMetresPerMm * u.error_mm) + ", more than 1 % of the sag (" +
                           mm(units::kMetresPerMm * u.sag_mm) +
                           "); raise material.young_kpa or set material.gravity_compensation to false");
}

}  // namespace pneumo
