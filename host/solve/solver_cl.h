#pragma once
// The four solvers of solver.h on an OpenCL device (kernels/msd_forces.cl, msd_integrators.cl):
// float32, the state resident on the device across steps; only the few scalars convergence needs
// (max |F|, max |v|, max displacement, FIRE's power and norms, Newmark's change) come back, every
// monitor_every steps (FIRE: every step, three numbers). The 2004 scheme updates all nodes at once
// (Jacobi) on the device, where the CPU reference goes node by node (Gauss–Seidel), as method.md §6
// says; both stop at the same tolerance, so they reach the same equilibrium.
#include <cstdint>
#include <memory>
#include <vector>

#include "cl/cl_runtime.h"
#include "solve/solver.h"

namespace pneumo {

/// Same contract as solve(): same options, same result fields, same DivergedError messages.
SolveResult solve_opencl(ocl::Context& ctx, const Mesh& m, const SolveOptions& opt,
                         const std::vector<Vec3>& x_start = {});

/// The device memory a solve of `m` is checked against before it allocates anything (bytes): at
/// least what any of the four solvers allocates.
uint64_t solver_device_bytes(const Mesh& m);

/// For benchmarks: explicit steps with everything on the device and nothing read back.
class ClExplicitStepper {
 public:
  ClExplicitStepper(ocl::Context& ctx, const Mesh& m, const ForceModel& model, double dt_s);
  ~ClExplicitStepper();
  ClExplicitStepper(const ClExplicitStepper&) = delete;
  ClExplicitStepper& operator=(const ClExplicitStepper&) = delete;
  void steps(int n);   // enqueues n steps (force evaluation + update each)
  void finish();       // waits for the device
 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pneumo
