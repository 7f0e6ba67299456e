#pragma once
// Newton's linear solve on an OpenCL device (newton_linear_solver.h): the block-Jacobi preconditioned
// conjugate gradients of conjugate_gradients.cpp with every node vector on the device
// (kernels/newton_cg.cl), float32, around the finite elements' stiffness product there
// (fem_force_field_cl.h), plus the pressure's stiffness, the wall–viscera bonds and the shift. Per
// Newton iteration the host sends the right-hand side, the preconditioner and the pressure's pair
// vectors and takes the step back; per conjugate-gradient step only three dot products come back, as
// 256 partial sums each, added in double. The preconditioner is inverted on the host (block_jacobi),
// so both solvers precondition alike.
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "cl/cl_runtime.h"
#include "solve/interface_tie.h"
#include "solve/newton_linear_solver.h"

namespace pneumo {

/// What a device force field gives the solver: `field` linearises and answers its diagonal blocks
/// (ForceField), `product` computes its own K p from device buffers of m.node_count() float4 into another.
struct DeviceStiffness {
  ForceField* field = nullptr;
  std::function<void(const cl::Buffer& p, cl::Buffer& kp)> product;
};

/// The solver on ctx for mesh m with the bonds `ties`. Checks the device memory it needs first.
std::unique_ptr<NewtonLinearSolver> make_newton_linear_solver_cl(ocl::Context& ctx, const Mesh& m, DeviceStiffness k,
                                                                 std::vector<TiedPair> ties);

/// What it allocates on the device (bytes).
uint64_t newton_linear_solver_cl_bytes(const Mesh& m, std::size_t ties);

}  // namespace pneumo
