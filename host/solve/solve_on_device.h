#pragma once
// The one entry through which the pipeline and the benchmarks solve: the device is chosen here,
// not by each caller. A new back end is a new case here.
#include <memory>
#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "solve/solver.h"

namespace pneumo {

/// Whether OpenCL implements this method and material model: the springs' four schemes
/// (solver_cl.h) and Newton on the finite elements (fem_force_field_cl.h, the conjugate gradients on
/// the host); Newton on the springs runs on the CPU.
bool device_implements(const SolveOptions& opt);

/// Why OpenCL cannot solve these options ("" when it can): one sentence naming what it does solve. With
/// the mesh, also what only the mesh says (the springs have no chest beyond a cut on the device).
std::string device_shortfall(const SolveOptions& opt, const Mesh* m = nullptr);

/// InputError when OpenCL device `device` (its spec, as the user wrote or the context names it)
/// cannot solve these options and opt.allow_cpu_fallback is not set: the one refusal, shared by
/// solve_on_device and the pipeline's check before the roles are built.
void require_device_solves(const std::string& device, const SolveOptions& opt);

/// The force field a device's Newton runs on: the finite elements on `ctx` (fem_force_field_cl.h) with
/// contact, the interface bond and the chest beyond the cut where `model` and m have them, wrapped
/// exactly as make_force_field wraps the host's. Finite-element models only.
std::unique_ptr<ForceField> make_device_force_field(ocl::Context& ctx, const Mesh& m, const ForceModel& model);

/// Solves on `ctx` when it is given and implements the options, on the CPU without one. Given one that
/// does not implement them: InputError naming the choice, unless opt.allow_cpu_fallback, then on the
/// CPU, saying so once per process and in SolveResult::device_fallback. SolveResult::device is where
/// it ran, never only what was asked for.
SolveResult solve_on_device(ocl::Context* ctx, const Mesh& m, const SolveOptions& opt,
                            const std::vector<Vec3>& x_start = {});

}  // namespace pneumo
