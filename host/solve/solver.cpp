#include "solve/solver.h"

#include <cmath>
#include <ostream>

#include "core/error.h"
#include "core/units.h"
#include "solve/solver_common.h"

namespace pneumo {

// Defined in one file per scheme.
SolveResult solve_explicit(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x);
SolveResult solve_newmark(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x);
SolveResult solve_kitasaka2004(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x);
SolveResult solve_static_fire(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x);
SolveResult solve_newton(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x);
SolveResult solve_implicit_euler(const Mesh& m, const SolveOptions& opt, std::vector<Vec3> x);

double stable_time_step(const Mesh& m, bool damping) {
  std::vector<double> ksum(m.node_count(), 0.0), csum(m.node_count(), 0.0);
  for (std::size_t s = 0; s < m.springs.size(); ++s)
    for (int32_t n : m.springs[s]) {
      ksum[n] += m.spring_k[s];
      csum[n] += damping ? m.spring_c[s] : 0.0;
    }
  double dt = INFINITY;
  for (int64_t n = 0; n < m.node_count(); ++n) {
    if (m.hold[n] == kHoldAll || !(ksum[n] > 0.0)) continue;
    const double omega = std::sqrt(2.0 * ksum[n] / m.mass_kg[n]);
    const double xi = csum[n] / (m.mass_kg[n] * omega);
    dt = std::min(dt, 2.0 / omega * (std::sqrt(1.0 + xi * xi) - xi));
  }
  return dt;
}

const char* stop_reason_text(StopReason r) {
  switch (r) {
    case StopReason::Converged: return "converged";
    case StopReason::StepLimit: return "step limit";
    case StopReason::InvertedTetrahedra: return "inverted tetrahedra";
    case StopReason::NoDescent: return "no descent";
  }
  return "unknown";
}

std::ostream& operator<<(std::ostream& os, StopReason r) { return os << stop_reason_text(r); }

double ramp_factor(double t_s, double ramp_s, RampShape shape) {
  if (!(ramp_s > 0.0) || t_s >= ramp_s) return 1.0;
  const double tau = std::max(0.0, t_s / ramp_s);
  return shape == RampShape::Linear ? tau : 0.5 * (1.0 - std::cos(M_PI * tau));
}

SolveFootprint solve_host_footprint(const SolveOptions& opt) {
  const bool elements = opt.forces.material != MaterialModel::Msd;
  return SolveFootprint{640, elements ? 640u : 64u};
}

SolveResult solve(const Mesh& m, const SolveOptions& opt, const std::vector<Vec3>& x_start) {
  std::vector<Vec3> x = x_start.empty() ? m.rest_m : x_start;
  if (opt.forces.tie_attached && !solves_force_fields(opt.method))
    throw InputError(std::string("mesh.attached_labels needs solver.method \"static\", \"newton\" or \"implicit-euler\", not \"") +
                     enum_name(opt.method) + "\"");
  if (opt.forces.contact_stiffness > 0.0 && !solves_force_fields(opt.method))
    throw InputError(std::string("contact needs solver.method \"static\", \"newton\" or \"implicit-euler\", not \"") +
                     enum_name(opt.method) + "\"");
  // The explicit and Newmark schemes take their stable step and damping from the springs, the 2004
  // scheme their stiffness sums: the finite elements have neither (scene_validate.cpp refuses it too).
  if (opt.forces.material != MaterialModel::Msd && !solves_force_fields(opt.method))
    throw InputError(std::string("material model \"") + enum_name(opt.forces.material) + "\" needs solver.method "
                     "\"static\", \"newton\" or \"implicit-euler\", not \"" + enum_name(opt.method) + "\"");
  switch (opt.method) {
    case SolverMethod::Explicit: return solve_explicit(m, opt, std::move(x));
    case SolverMethod::Newmark: return solve_newmark(m, opt, std::move(x));
    case SolverMethod::Kitasaka2004: return solve_kitasaka2004(m, opt, std::move(x));
    case SolverMethod::Static: return solve_static_fire(m, opt, std::move(x));
    case SolverMethod::Newton: return solve_newton(m, opt, std::move(x));
    case SolverMethod::ImplicitEuler: return solve_implicit_euler(m, opt, std::move(x));
  }
  throw std::logic_error("unknown solver");
}

}  // namespace pneumo
