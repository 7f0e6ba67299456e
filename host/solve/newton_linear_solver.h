#pragma once
// Newton's linear solve (solve_newton.cpp): (K + σD) d = f at a state, K = −∂f/∂x the force field's
// stiffness and the gas pressure's (pressure_stiffness.h), D its diagonal blocks, by block-Jacobi
// preconditioned conjugate gradients (conjugate_gradients.h) to the relative residual η, with the
// Levenberg–Marquardt shift grown where K is indefinite. Two implementations: on the host, any force
// field through its stiffness product; on an OpenCL device where the field keeps its state there
// (newton_cl.h), so that a conjugate-gradient step moves no node vector between host and device.
#include <memory>
#include <vector>

#include "mesh/mesh.h"
#include "solve/conjugate_gradients.h"

namespace pneumo {

class ForceField;
struct ForceModel;

class NewtonLinearSolver {
 public:
  virtual ~NewtonLinearSolver() = default;
  /// Prepares K at x under `model` (its pressure included) and the preconditioner.
  virtual void linearize(const ForceModel& model, const std::vector<Vec3>& x) = 0;
  /// d with |(K + σD) d − b| ≤ η |b| on the free axes (b's held axes zero), σ from `shift` and grown
  /// as shifted_conjugate_gradients grows it; `iterations` counts every attempt's.
  virtual CgOutcome solve(const std::vector<Vec3>& b, double eta, int max_iterations, Shift& shift,
                          std::vector<Vec3>& d) = 0;
};

/// The host's: `field`'s stiffness product and diagonal plus PressureStiffness, solved by
/// shifted_conjugate_gradients on node vectors in double. `m` and `field` must outlive it.
std::unique_ptr<NewtonLinearSolver> host_newton_linear_solver(const Mesh& m, ForceField& field);

/// The device's when `field` offers one (ForceField::device_linear_solver), the host's otherwise.
std::unique_ptr<NewtonLinearSolver> newton_linear_solver(const Mesh& m, ForceField& field);

}  // namespace pneumo
