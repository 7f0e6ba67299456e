#pragma once
// The finite elements' stiffness K = −∂f/∂x assembled at one linearisation (a third implementation of
// the product beside the CPU reference's matrix-free one and the OpenCL field's; tested against the
// reference in tests/test_fem_stiffness_assembly.cpp).
//
// Why: the matrix-free product (fem_force_field.cpp) evaluates every tetrahedron's tangent δP(δF)
// on each call, and Newton's CG calls it 50–100 times per step at one state. Assembled once per
// step, each product is a sparse multiply of 3×3 blocks.
//
// What is assembled, for each group c of the mean dilatation (fem_force_field.cpp's equations),
// with ∇N_i the gradients of tetrahedron t's shape functions (the rows of D_m⁻¹; vertex 0 minus
// their sum) and V_t its rest volume:
//   the tetrahedron's own tangent, block (i, j) column b = V_t (δP_d + κ_t ē_c δG)(e_b ⊗ ∇N_j) ∇N_i;
//   the cube's mean dilatation, rank one: b_c b_cᵀ / Λ_c, with b_c,i = Σ_t κ_t V_t G_t ∇N_i,
// since δē_c = b_c · p / Λ_c and the term's forces are δē_c b_c. K is symmetric (the Hessian of the
// elastic energy; asymmetric to 1e-16 of its largest block as computed), so only its upper triangle
// is kept.
#include <cstdint>
#include <optional>
#include <vector>

#include "mesh/mesh.h"
#include "solve/symmetric_block_csr.h"
#include "solve/fem_element.h"
#include "solve/fem_tets.h"

namespace pneumo {

class FemStiffnessAssembly {
 public:
  /// The assembly for `groups`, or nothing when its blocks could exceed `budget_bytes`: the bound
  /// counts each group's n_g (n_g + 1) / 2 pairs apart, so it overestimates the shared ones.
  static std::optional<FemStiffnessAssembly> within(const Mesh& m, const FemGroups& groups, int64_t budget_bytes);

  /// K at the element states `state` and the groups' mean dilatations `ebar`.
  void assemble(const FemTets& tets, const FemGroups& groups, const std::vector<ElementState>& state,
                const std::vector<double>& ebar);
  /// kp = K p at the last assembly.
  void multiply(const std::vector<Vec3>& p, std::vector<Vec3>& kp) const { k_.multiply(p, kp); }
  const SymmetricBlockCsr& matrix() const { return k_; }

 private:
  FemStiffnessAssembly() = default;
  // Group g's distinct nodes are nodes_[node_begin_[g]] …; its local block (a, b) lands in
  // k_.block[slot_[slot_begin_[g] + a n_g + b]] (−1 below the diagonal); vertex i of tetrahedron t is
  // local node local_[4t + i].
  std::vector<int64_t> node_begin_, slot_begin_, slot_;
  std::vector<int32_t> nodes_;
  std::vector<uint8_t> local_;
  SymmetricBlockCsr k_;
};

}  // namespace pneumo
