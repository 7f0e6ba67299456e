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

}  // namespace pneumo
