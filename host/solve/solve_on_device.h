#pragma once
// The one entry through which the pipeline and the benchmarks solve: the device is chosen here,
// not by each caller. A new back end is a new case here.
#include <vector>

#include "cl/cl_runtime.h"
#include "solve/solver.h"

namespace pneumo {

/// Whether OpenCL implements this method and material model: the springs' four schemes
/// (solver_cl.h) and Newton on the finite elements (fem_force_field_cl.h, the conjugate gradients on
/// the host); Newton on the springs runs on the CPU.
bool device_implements(const SolveOptions& opt);

/// Solves on `ctx` when it is given and implements the options, on the CPU otherwise (saying so
/// once per process when a device was asked for).
SolveResult solve_on_device(ocl::Context* ctx, const Mesh& m, const SolveOptions& opt,
                            const std::vector<Vec3>& x_start = {});

}  // namespace pneumo
