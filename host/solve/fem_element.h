#pragma once
// The constitutive laws of the tetrahedral finite elements (docs/fem.md), on one
// element's deformation gradient F = D_s D_m⁻¹ (D_s, D_m the current and rest edge matrices). Plain
// double-precision reference code. Each law is split into a deviatoric part ψ_d(F) and a dilatation
// measure e(F) with the volumetric energy ½λe², so that the volumetric part can be averaged over a
// cube (mean dilatation, fem_forces.h) against the volumetric locking of linear tetrahedra:
//   ψ = ψ_d(F) + ½ κ e(F)²,   P = ∂ψ/∂F = P_d + κ e G,   G = ∂e/∂F,
// with κ the law's volumetric modulus (volumetric_modulus()).
//
// Co-rotational linear elasticity (as SOFA's TetrahedronFEMForceField, with the polar rotation):
//   F = R S (polar; R a rotation, S symmetric, with a negative eigenvalue for an inverted element,
//   which then pushes back: Irving et al. 2004),
//   ψ_d = μ‖F − R‖²,  P_d = 2μ(F − R),  e = tr(S) − 3,  G = R,  κ = λ.
// Their derivatives need δR = R[ω]× with (tr(S) I − S) ω = axial(RᵀδF − δFᵀR) (McAdams et al. 2011),
// so the stiffness product is the exact Jacobian, not SOFA's frozen-rotation approximation.
//
// Neo-Hookean in the decoupled form, with Demiray's exponential stiffening of the isochoric part
// (Demiray 1972; b = 0 is the plain neo-Hookean, Holzapfel 2000 §6.5), J = det F, Ī₁ = J^{−2/3} tr(FᵀF):
//   ψ_d = μ/(2b) (e^{b(Ī₁−3)} − 1)   (μ/2 (Ī₁ − 3) at b = 0),   e = ln J,  G = F⁻ᵀ,  κ = λ + ⅔μ,
//   P_d = (μ/2) e^{b(Ī₁−3)} ∂Ī₁/∂F,   ∂Ī₁/∂F = J^{−2/3} (2F − ⅔ I₁ F⁻ᵀ).
// The isochoric invariant keeps the small-strain bulk modulus κ whatever b (with I₁ itself, b would
// add 2bμ to it). J ≤ 0 has no energy (the element is inverted): the caller treats it as such.
// Both laws reduce to Hooke's law with Lamé's μ and λ at small strain.
//
// Either law may carry one family of collagen fibres along the unit rest direction a₀, in the
// Holzapfel–Gasser–Ogden form (Holzapfel, Gasser & Ogden 2000, J Elasticity 61:1) with the full
// fourth invariant I₄ = a₀·C a₀ = |F a₀|², not its isochoric part: Nolan et al. 2014 (J Mech Behav
// Biomed Mater 39:48) show that the isochoric Ī₄ leaves a compressible fibre-reinforced material without
// any response to a stretch along its fibres at constant volume. It adds to the deviatoric part
// (it is no measure of dilatation, so the mean dilatation leaves it alone):
//   ψ_f = k₁/(2k₂) (e^{k₂(I₄−1)²} − 1)   (k₁/2 (I₄−1)² at k₂ = 0), for I₄ ≥ 1 only: fibres carry no compression,
//   P_f = 2ψ'(I₄) (F a₀) ⊗ a₀,   ψ' = k₁ (I₄−1) e^{k₂(I₄−1)²},
//   δP_f = 2ψ' (δF a₀) ⊗ a₀ + 4ψ'' ((F a₀)·(δF a₀)) (F a₀) ⊗ a₀,   ψ'' = k₁ (1 + 2k₂(I₄−1)²) e^{k₂(I₄−1)²}.
// At rest (I₄ = 1) the stiffness is the tension side's, as for the contact's kink (contact.h), so a
// Newton step from rest sees the fibres it will stretch. At small strain the fibres add 4k₁ ε_aa² to
// the energy: a uniaxial stretch along them at constant volume meets E = 3μ + 4k₁, across them 3μ.
#include <array>
#include <cstdint>

#include "core/geometry.h"

namespace pneumo {

enum class FemLaw : uint8_t { Corotational, NeoHookean };

/// One tetrahedron's material: Lamé's parameters and its fibre family (none where fibre_k1_pa is 0).
struct TetMaterial {
  double mu = 0, lambda = 0;
  Vec3 fibre = Vec3::Zero();   // a₀, the fibres' unit direction at rest
  double fibre_k1_pa = 0;      // k₁ of ψ_f
  double fibre_k2 = 0;         // k₂ of ψ_f (dimensionless)
  /// Lamé's parameters from Young's modulus and Poisson's ratio: μ = E/(2(1+ν)), λ = Eν/((1+ν)(1−2ν)).
  static TetMaterial from_young_poisson(double young_pa, double poisson) {
    return {young_pa / (2.0 * (1.0 + poisson)), young_pa * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson))};
  }
};

/// The polar decomposition F = R S with R a proper rotation (det R = +1), from the SVD F = U Σ Vᵀ with
/// the sign of the smallest singular value flipped when det F < 0. V and Σ are kept for δR.
struct Polar {
  Mat3 R, S, V;
  Vec3 sigma;
};
Polar polar_decomposition(const Mat3& F);

/// What the derivatives of one element reuse, computed once per deformation gradient.
struct ElementState {
  FemLaw law = FemLaw::Corotational;
  Mat3 F;
  Mat3 R;                 // co-rotational: the polar rotation
  Mat3 omega_inverse;     // co-rotational: (tr(S) I − S)⁻¹, regularised for a flat element
  Mat3 F_inverse_t;       // neo-Hookean: F⁻ᵀ
  double e = 0;           // the dilatation measure
  double j23 = 1;         // neo-Hookean: J^{−2/3}
  double i1 = 3;          // neo-Hookean: tr(FᵀF)
  double exponential = 1; // neo-Hookean: e^{b(Ī₁−3)}
  double b = 0;
  bool valid = true;      // false: neo-Hookean with J ≤ 0
};
ElementState element_state(FemLaw law, const Mat3& F, double stiffening_b = 0.0);

/// κ of the volumetric energy ½κe²: λ (co-rotational) or the bulk modulus λ + ⅔μ (neo-Hookean).
double volumetric_modulus(FemLaw law, const TetMaterial& m);
double deviatoric_energy_density(const ElementState& s, const TetMaterial& m);   // +∞ when !valid
Mat3 deviatoric_piola(const ElementState& s, const TetMaterial& m);
Mat3 deviatoric_dpiola(const ElementState& s, const Mat3& dF, const TetMaterial& m);
/// G = ∂e/∂F and δG for δF.
Mat3 dilatation_gradient(const ElementState& s);
Mat3 dilatation_dgradient(const ElementState& s, const Mat3& dF);

/// The whole law on one element (no averaging): ψ, P and δP.
double energy_density(const ElementState& s, const TetMaterial& m);
Mat3 piola(const ElementState& s, const TetMaterial& m);
Mat3 dpiola(const ElementState& s, const Mat3& dF, const TetMaterial& m);

/// A tetrahedron's rest data: D_m⁻¹ and volume (m³) from its four rest vertices.
struct TetRest {
  Mat3 dm_inverse;
  double volume_m3 = 0;
};
TetRest tet_rest(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3);
/// D_s of the current vertices (columns x_i − x₀).
Mat3 edge_matrix(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3);
/// The four nodal forces of stress P on a tetrahedron: vertices 1–3 the columns of −V₀ P D_m⁻ᵀ,
/// vertex 0 minus their sum.
std::array<Vec3, 4> nodal_forces(const Mat3& P, const TetRest& rest);
/// ∇N_i of the four linear shape functions: the rows of D_m⁻¹ for vertices 1–3, vertex 0 minus their
/// sum (so δF = Σ_i δx_i ⊗ ∇N_i).
std::array<Vec3, 4> shape_gradients(const TetRest& rest);

}  // namespace pneumo
