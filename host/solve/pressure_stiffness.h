#pragma once
// The gas pressure's stiffness for the Newton solver: K_p = −∂f_p/∂x, with f_p the follower load of
// mesh.h, f_i = −P · cof(D_s) · c_i on each load's tetrahedron.
//
// With e_k = x_k − x_0 the edges and cof(D_s) c = c₁ e₂×e₃ + c₂ e₃×e₁ + c₃ e₁×e₂ (pressure_load.cpp),
//   δ(cof(D_s) c_i) = Σ_k w_ik × δe_k,  w_i1 = c_i2 e₃ − c_i3 e₂,  w_i2 = c_i3 e₁ − c_i1 e₃,  w_i3 = c_i1 e₂ − c_i2 e₁,
// so the 3×3 block of vertex j in row i is K_ij = P [W_ij]× (W_ik = w_ik for k ≥ 1, W_i0 = −Σ_k w_ik).
// The load is the gradient of P times the gas volume where the cavity surface is closed or its rim
// held (method.md §5): there K_p is symmetric, the Hessian of −P V. Per load it is not, and CG needs
// a symmetric matrix, so each load contributes its symmetric part ½(K + Kᵀ), whose blocks are
// S_ij = [u_ij]× with u_ij = ½P (W_ij − W_ji): skew, with a zero diagonal. Summed over a closed
// surface this is K_p exactly; on an open rim it drops only the antisymmetric part there.
#include <array>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {

class PressureStiffness {
 public:
  /// Prepares the product at positions x and pressure P (Pa); P = 0 makes it zero.
  void linearize(const Mesh& m, const std::vector<Vec3>& x, double pressure_pa);
  /// kp += S p, S the symmetric part of K_p at the last linearisation.
  void add_product(const std::vector<Vec3>& p, std::vector<Vec3>& kp) const;
  /// Per load, u_ij for the pairs (0,1), (0,2), (0,3), (1,2), (1,3), (2,3) of its tetrahedron's
  /// vertices (empty at P = 0): what a device computes S p from (kernels/newton_cg.cl).
  const std::vector<std::array<Vec3, 6>>& pairs() const { return u_; }

 private:
  const Mesh* m_ = nullptr;
  // Per load, u_ij for the pairs (0,1), (0,2), (0,3), (1,2), (1,3), (2,3) (u_ji = −u_ij).
  std::vector<std::array<Vec3, 6>> u_;
};

}  // namespace pneumo
