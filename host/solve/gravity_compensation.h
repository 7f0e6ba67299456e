#pragma once
// Gravity compensation (Bano 2012, "inverse gravitational deformation"): the CT shows the body
// already loaded by its weight, so gravity applied to the CT's shape would sag it a second time.
// Instead the solve starts from an unloaded rest shape X* whose equilibrium under gravity is the CT:
// x(X*) = x_CT. Bano took X* as the CT deformed by a negative gravity, one step; here that step is
// repeated as a fixed point (Sellier 2011; Bols et al. 2013, "backward displacement"):
//
//   X_0 = x_CT,   x_k = the equilibrium under gravity from rest shape X_k,   X_{k+1} = X_k + (x_CT − x_k),
//
// whose first step is Bano's to first order and which converges linearly at the rate by which the
// sag changes with the shape (geometric and material nonlinearity; for a linear model, one step).
// It stops when the CT is recovered to 1 % of the sag gravity alone would add (the sag is what a user
// wants compensated; 1 % of it is below what the 1e-3 residual of each solve resolves in most runs),
// or at 10 steps: then it throws, saying by how much it missed.
#include <functional>
#include <vector>

#include "mesh/mesh.h"
#include "solve/solver.h"

namespace pneumo {

/// A static solve of mesh m from x_start (the pipeline's device or the CPU reference).
using StaticSolveFn = std::function<SolveResult(const Mesh& m, const SolveOptions& opt, const std::vector<Vec3>& x_start)>;

struct UnloadedShape {
  Mesh mesh;                 // the CT's mesh at the rest shape X*
  double sag_mm = 0;         // the largest node displacement gravity adds to the CT's own shape
  double error_mm = 0;       // the largest |x(X*) − x_CT| left
  int iterations = 0;        // solves under gravity
  int64_t solver_steps = 0;  // their steps together
  double wall_time_s = 0;
};

/// The unloaded rest shape of `ct` under opt.forces.gravity_m_s2 (must be non-zero), with no gas
/// pressure and the wall bonded to the viscera (interface_tie.h): every solve by `solve`, by Newton when
/// opt's method is "newton", by FIRE ("static") otherwise. Throws std::runtime_error when a solve
/// does not converge, a rest shape turns inside out or 10 steps leave more than 1 % of the sag.
UnloadedShape unloaded_shape(const Mesh& ct, const SolveOptions& opt, const StaticSolveFn& solve);

}  // namespace pneumo
