#pragma once
// The solvers of method.md §6, sharing one force evaluation: explicit (symplectic Euler),
// Newmark-β with its inner loop (Nimura), the 2004 quasi-static scheme (Kitasaka) and a fast static
// solver (FIRE). The plain C++ reference; SI units inside (m, s, N, Pa).
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <stdexcept>
#include <string>
#include <vector>

#include "mesh/mesh.h"
#include "domain/types.h"
#include "solve/forces.h"

namespace pneumo {

/// The state a solver shows its observer (checkpoints, the inflation preview) at monitoring steps.
struct SolverSnapshot {
  int64_t step = 0;
  double time_s = 0, pressure_pa = 0;   // time 0 for the static schemes
  const std::vector<Vec3>& x;           // positions (m)
};

struct SolveOptions {
  SolverMethod method = SolverMethod::Static;
  ForceModel forces;                 // pressure_pa is the target pressure
  double dt_s = 0.0;                 // 0 = dt_safety × the stability estimate
  double dt_safety = 0.5;
  int64_t max_steps = 100000;
  double residual_tolerance = 1e-3;  // max |free net force| / reference load
  double velocity_tolerance_m_s = 5e-4;
  int hold_steps = 50;               // convergence must hold this many consecutive steps
  double ramp_s = 0.5;               // pressure ramp duration (dynamic solvers)
  // The pressure the start state is in equilibrium with: ramps and load increments run from it to
  // forces.pressure_pa (a pressure–volume curve solves each pressure from the last equilibrium).
  double start_pressure_pa = 0.0;
  RampShape ramp_shape = RampShape::Smooth;
  double newmark_beta = 0.25, newmark_gamma = 0.5;
  double newmark_inner_tolerance = 1e-6;
  int newmark_max_inner = 50;
  int newton_max_cg_iterations = 500;
  double rayleigh_mass_per_s = 0.1, rayleigh_stiffness_s = 0.1;   // implicit Euler: C = α M + β K
  double kitasaka_step = 0.3;
  double kitasaka_tolerance_m = 1e-3;  // β: Σ|ΔR_i| over all nodes
  bool kitasaka_jacobi = false;        // CPU reference: all nodes from the same forces, as the device does
  OnInverted on_inverted = OnInverted::Continue;
  int64_t monitor_every = 10;        // convergence/inversion checks every N steps
  // Called at the first monitoring step at or past every snapshot_every_steps steps (0: never).
  // On a device the positions are downloaded for it; what it does is not timed as solving.
  int64_t snapshot_every_steps = 0;
  std::function<void(const SolverSnapshot&)> on_snapshot;
  bool progress = true;
  // A device asked for that does not implement the method and model (solve_on_device.h): false refuses
  // the solve with an InputError; true solves on the CPU and says so in SolveResult::device_fallback.
  bool allow_cpu_fallback = false;
};

/// Host memory a solve allocates beside its mesh, per node and per tetrahedron: an allowance for the
/// largest scheme (Newton: positions, trial, forces and direction, CG's four vectors, the diagonal
/// blocks and their inverses: about 12 Vec3 and 2 Mat3 a node, rounded up to 640 B), and for the
/// elements' states (F, R, Ω⁻¹, F⁻ᵀ, δF, rest, Lamé: about 620 B a tetrahedron) or the springs'
/// per-tetrahedron share. Checked with the mesh before either is built (mesh.h, MeshOptions).
struct SolveFootprint {
  uint64_t per_node = 0, per_tet = 0;
};
SolveFootprint solve_host_footprint(const SolveOptions& opt);

struct SolveSample {              // one row of the convergence history
  int64_t step = 0;
  double time_s = 0, pressure_pa = 0, residual = 0, max_displacement_m = 0, max_speed_m_s = 0;
};

/// Why a solve stopped. stop_reason_text() is the one place each is spelled (progress lines,
/// metrics.json, messages); code compares the values, never the text.
enum class StopReason : uint8_t {
  Converged,           // residual (and, dynamic, speed) below tolerance at the full load
  StepLimit,           // solver.max_steps reached first
  InvertedTetrahedra,  // solver.on_inverted = "stop" and a tetrahedron turned inside out
  NoDescent,           // Newton: the line search found no step that lowers the energy
};
const char* stop_reason_text(StopReason r);
std::ostream& operator<<(std::ostream& os, StopReason r);   // the text, for test messages

struct SolveResult {
  std::vector<Vec3> x;            // final positions (m)
  std::vector<Vec3> v;            // final velocities (m/s; zero for the static schemes)
  bool converged = false;
  StopReason stop_reason = StopReason::StepLimit;   // converged == (stop_reason == Converged)
  std::string solver;
  int64_t steps = 0, force_evaluations = 0, inner_iterations = 0;
  double wall_time_s = 0, residual = 0, dt_s = 0, dt_stable_s = 0, final_pressure_pa = 0;
  int64_t inverted_tetrahedra = 0;
  std::vector<SolveSample> history;
  std::string device = "cpu";       // where it ran: "cpu", or "opencl:P:D <name>" (solve_on_device.h)
  std::string device_fallback;      // why the device asked for did not run it; empty when it did
};

/// A run that blew up. The message names the parameter to change and the largest stable step.
class DivergedError : public std::runtime_error {
 public:
  DivergedError(const std::string& what, double dt_stable_s)
      : std::runtime_error(what), dt_stable_s(dt_stable_s) {}
  double dt_stable_s;
};

/// Largest stable explicit time step (§6): min over nodes of (2/ω_i)(√(1+ξ_i²) − ξ_i) with
/// ω_i² = 2Σ_j k_ij/m_i (Gershgorin) and ξ_i = Σ_j c_ij/(m_i ω_i).
double stable_time_step(const Mesh& m, bool damping);

/// Pressure ramp factor r(t/T) in [0,1] (§6): linear or (1 − cos πτ)/2, then 1.
double ramp_factor(double t_s, double ramp_s, RampShape shape);

/// Runs the chosen solver from `x_start` (rest positions when empty).
SolveResult solve(const Mesh& m, const SolveOptions& opt, const std::vector<Vec3>& x_start = {});

class ForceField;
/// Newton (solve_newton.cpp) on a given force field, e.g. one on an OpenCL device
/// (fem_force_field_cl.h); x_start empty is the rest state.
SolveResult solve_newton_on(const Mesh& m, const SolveOptions& opt, ForceField& field,
                            const std::vector<Vec3>& x_start = {});

}  // namespace pneumo
