#pragma once
// The linear algebra the implicit solvers share (Newton, implicit Euler): block-Jacobi preconditioned
// conjugate gradients on node vectors, matrix-free. Held axes (mesh.hold) are masked out.
#include <functional>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {

/// Σ a_i · b_i over the nodes.
double dot(const std::vector<Vec3>& a, const std::vector<Vec3>& b);

/// The inverse of each node's diagonal block on its free axes (held axes: zero rows and columns); a
/// block that is not positive falls back to the inverse of its diagonal.
std::vector<Mat3> block_jacobi(const Mesh& m, const std::vector<Mat3>& blocks);

struct CgOutcome {
  int iterations = 0;
  bool negative_curvature = false;   // stopped at pᵀAp ≤ 0, keeping what it had
};

/// y = A p for a symmetric A (held axes are masked after it).
using LinearOperator = std::function<void(const std::vector<Vec3>& p, std::vector<Vec3>& y)>;

/// Solves A d = b to |b − A d| ≤ η |b| on the free axes, preconditioned by `precond` (block_jacobi).
CgOutcome conjugate_gradients(const Mesh& m, const LinearOperator& A, const std::vector<Mat3>& precond,
                              const std::vector<Vec3>& b, double eta, int max_iterations, std::vector<Vec3>& d);

/// The shift σ of a matrix that may be indefinite (Newton, implicit Euler): CG on A + σ D, D the
/// diagonal blocks of A, with σ grown tenfold from 10⁻³ while CG meets negative curvature, up to 10³
/// (a Levenberg–Marquardt shift towards scaled steepest descent). It carries over between solves;
/// relax() shrinks it tenfold after a solve the caller judged good.
struct Shift {
  double sigma = 0.0;
  void relax() { sigma = sigma > kFirst ? 0.1 * sigma : 0.0; }
  static constexpr double kFirst = 1e-3, kMax = 1e3;
};
/// The shift's growth around any CG: calls cg(σ), which solves (A + σ D) d = b once, with σ grown tenfold
/// from 10⁻³ while it meets negative curvature, up to 10³; `iterations` counts every attempt's.
CgOutcome with_growing_shift(Shift& shift, const std::function<CgOutcome(double sigma)>& cg);

/// Solves (A + σ D) d = b as conjugate_gradients does, growing `shift` as it needs; `iterations`
/// counts every attempt's. negative_curvature is set only when even σ = 10³ did not make CG complete.
CgOutcome shifted_conjugate_gradients(const Mesh& m, const LinearOperator& A, const std::vector<Mat3>& blocks,
                                      const std::vector<Mat3>& precond, const std::vector<Vec3>& b, double eta,
                                      int max_iterations, Shift& shift, std::vector<Vec3>& d);

}  // namespace pneumo
