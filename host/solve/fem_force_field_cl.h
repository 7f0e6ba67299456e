#pragma once
// The finite elements of fem_force_field.cpp on an OpenCL device (kernels/fem_forces.cl), float32,
// behind the same ForceField interface, so Newton (solve_newton.cpp) solves with it unchanged. The
// mesh, the element states and the group averages stay on the device; each call moves one node
// vector up (positions as displacements, or a direction) and one down (forces or K p). Newton's
// linear solve runs on the device too (device_linear_solver, newton_cl.h), around the same product on
// device buffers. Pressure loads use msd_forces.cl's load_pressure.
#include <memory>

#include "cl/cl_runtime.h"
#include "solve/force_field.h"

namespace pneumo {

/// The FEM force field of `model` on `ctx`. Checks the device memory it needs first (InputError with
/// the estimate if it does not fit).
std::unique_ptr<ForceField> make_fem_force_field_cl(ocl::Context& ctx, const Mesh& m, MaterialModel model);

/// What it allocates on the device (bytes).
uint64_t fem_force_field_cl_bytes(const Mesh& m);

}  // namespace pneumo
