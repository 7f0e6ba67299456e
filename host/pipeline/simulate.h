#pragma once
// roles → mesh → solve for one scene: what `pneumo simulate` runs, and what the pipeline reuses.
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "mesh/mesh.h"
#include "pipeline/scene_stages.h"
#include "roles/roles.h"
#include "roles/scan_coverage.h"
#include "scene/scene.h"
#include "solve/solver.h"

namespace pneumo {

/// One point of a pressure–volume curve: the equilibrium at one pressure, reached from the last.
struct PressurePoint {
  double pressure_mmhg = 0, cavity_volume_ml = 0, anterior_rise_mm = 0, residual = 0, wall_time_s = 0;
  bool converged = false;
  int64_t steps = 0;
};

/// What gravity compensation found (solve/gravity_compensation.h), when it ran.
struct GravityCompensation {
  bool done = false;
  double sag_mm = 0, error_mm = 0, wall_time_s = 0;
  int iterations = 0;
  int64_t solver_steps = 0;
};

struct Simulation {
  RoleVolume roles;
  ScanCoverage coverage;                      // what the CT covers, in words (roles/scan_coverage.h)
  Mesh mesh;                                  // at the CT's shape: displacements are from it
  GravityCompensation gravity;
  SolveResult result;                         // at the scene's load.pressure_mmhg
  std::vector<PressurePoint> pressure_curve;  // when the scene lists pressures (§9), in order
  std::string device;            // where the solve ran: "cpu" or "opencl:P:D <name>"
  std::string device_fallback;   // why the scene's device did not run it (solver.allow_cpu_fallback); empty when it did
  InputVolumes inputs;  // the CT and labels as read, when prepare_simulation was asked to keep them
  double stage_seconds_roles = 0, stage_seconds_mesh = 0, stage_seconds_solve = 0;
};

/// Runs roles, mesh and the scene's solver on the scene's device (the CPU reference or OpenCL):
/// prepare_simulation then solve_simulation. A DivergedError propagates.
Simulation simulate_scene(const Scene& scene);

/// Roles and mesh (InputError when the mesh has no cavity faces). With `keep_inputs` the CT and
/// label map stay in Simulation::inputs for a later stage (a run's warp), instead of being read again.
Simulation prepare_simulation(const Scene& scene, bool keep_inputs = false);

/// What a caller adds to a solve: a start state (a resumed run's checkpoint) and an observer of
/// the solver's progress (checkpoints, the inflation preview).
struct SolveHooks {
  std::vector<Vec3> x_start;            // empty: the rest positions
  double start_pressure_pa = 0.0;       // the pressure x_start was reached at
  int64_t snapshot_every_steps = 0;
  std::function<void(const SolverSnapshot&)> on_snapshot;
};

/// A solve that solver.on_inverted = "stop" ended at the first inverted tetrahedra: short of an
/// equilibrium, so its shape is no result and nothing is written for it. The message counts them and
/// says what to change.
class InvertedStopError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The scene's solver on its device, into sim.result; InvertedStopError when it stopped for
/// inversion. With load.pressure_curve_mmhg, every listed pressure and load.pressure_mmhg are solved
/// in increasing order, each from the previous equilibrium (the start state then applies to none: a
/// curve starts from rest).
void solve_simulation(const Scene& scene, Simulation& sim, const SolveHooks& hooks = {});

/// Plausibility measures of a solved mesh (method.md §9): displacements of the wall, the largest
/// anterior rise of the wall, and the gas volume opened between the wall and the viscera.
struct DeformationMetrics {
  double max_wall_displacement_mm = 0, mean_wall_displacement_mm = 0, anterior_rise_mm = 0;
  double mean_viscera_displacement_mm = 0, mean_viscera_anterior_mm = 0;
  double anterior_viscera_posterior_motion_mm = 0;   // over the viscera's anterior half (cavity_measures.h)
  double cavity_volume_ml = 0;
  /// Change of the viscera's tissue volume, Σ fraction × (V − V_rest) over their tetrahedra: what
  /// they give up to the gas (negative when compressed). Nearly incompressible viscera keep it near 0.
  double viscera_volume_change_ml = 0;
  double max_fixed_displacement_mm = 0;
};
DeformationMetrics deformation_metrics(const Mesh& m, const std::vector<Vec3>& x);

/// The metrics.json of a simulation (keys listed in docs and tests).
nlohmann::json simulation_metrics(const Scene& scene, const Simulation& sim);

/// Plots (SVG): residual, largest displacement and pressure against step; cavity volume and anterior
/// rise against pressure.
std::string convergence_plot_svg(const SolveResult& r);
std::string pressure_curve_plot_svg(const std::vector<PressurePoint>& curve);

/// Writes mesh_initial.vtu and mesh_deformed.vtu (when output.write_meshes), convergence.csv/.svg,
/// scene_used.json, with a pressure curve pressure_volume.csv/.svg, deformation.bin (the node
/// displacements `pneumo warp` reads) and metrics.json (last) into `dir` (created if needed), each
/// atomically.
void write_simulation(const Scene& scene, const Simulation& sim, const std::string& dir);

}  // namespace pneumo
