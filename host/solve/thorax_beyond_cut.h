#pragma once
// The chest beyond a CT's cranial cut. A scan that stops at the liver or the lung bases cuts the
// viscera and lungs that, in the patient, go on up under the diaphragm into the chest. Holding that
// cut face on its normal (a sliding plane, the mirror image of the body beyond) makes the chest
// rigid: nothing the gas pushes can rise into it, where patients' diaphragm and liver rise. Leaving
// it free makes the chest empty, and the cut tissue's edge free to bulge out of it.
//
// Between the two is what the chest is at the end of a ventilated expiration: lungs open to the
// ventilator, their volume held by their elastic recoil against the pleural pressure. Push the
// diaphragm up by ΔV and the pleural pressure rises by ΔV / C, C the lungs' compliance (the rib cage
// held, as the model holds the ribs). The cut tissue beyond keeps its shape as the mirror kept it:
// the face moves into the chest as a whole, not as a free surface. Two energies over the face's nodes
// i, with a_i their shares of its area vector out towards the head (Mesh::thorax_node,
// thorax_area_m2), n its unit normal, s_i = n · (x_i − X_i) their normal displacements and
// w_i = |a_i| / A their weights:
//
//   the chest:   ½ ΔV² / C,            ΔV = Σ a_i · (x_i − X_i) = A s̄,   s̄ = Σ w_i s_i
//   the face:    ½ Σ k_i (s_i − s̄)²,   k_i = κ × node i's own stiffness (Lloyd), κ = 10
//
// The first is the pleural pressure ΔV/C on the whole face; the second holds the face's shape as the
// sliding plane did (κ as in the interface bond, interface_tie.h: a tenth of the tissue's own
// deformation), leaving its mean motion to the chest. In-plane motion costs nothing, as on a sliding
// cut. Both are quadratic: K = a aᵀ / C + n nᵀ ⊗ (diag k − k wᵀ − w kᵀ + (Σk) w wᵀ), applied as
// products and never assembled; its diagonal blocks join the preconditioner. Units: metres, m³/Pa.
#include <memory>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {

class ForceField;

/// The volume the cranial cut face has pushed into the chest at x (m³; negative: drawn out of it).
double thorax_volume_change_m3(const Mesh& m, const std::vector<Vec3>& x);

/// `inner` with the chest and the face's shape added where m has a cranial cut face that opens onto
/// the chest (Mesh::thorax_node, with its compliance); `inner` otherwise.
std::unique_ptr<ForceField> with_thorax_beyond_cut(const Mesh& m, std::unique_ptr<ForceField> inner);

}  // namespace pneumo
