#pragma once
// The abdominal wall's collagen fibres for the finite elements' fibre term (solve/fem_element.h).
//
// Song et al. 2006 (Surg Endosc 20:987; 18 patients at 12 mmHg) measured the inflated wall stiffer across
// the body than along it: 42.5 ± 9.0 kPa transversely against 22.5 ± 2.6 kPa sagittally. What runs across
// is the collagen of the flat muscles' aponeuroses: the external and internal obliques and the
// transversus abdominis end laterally in sheets whose fibres run round the trunk, wrap the rectus in its
// sheath and cross at the linea alba. So the wall's fibres here run circumferentially: at each wall
// tetrahedron, along ẑ × r̂, with r the tetrahedron's centre minus the body's axis at its height (the
// volume-weighted mean of the tetrahedra's centres in a 10 mm slab of world z), in the axial plane. One
// family serves the whole wall, rectus and flanks alike; the rectus's own cranio-caudal muscle fibres,
// passive under anaesthesia, and the obliques' ±45° slant are not represented (docs/fem.md, "Fibres").
// Which tetrahedra are the wall's shell (not the diaphragm, the lungs or the retroperitoneum, which are
// wall tissue too) the caller says (pipeline/scene_stages.cpp).
//
// k₁ is a multiple of each tetrahedron's own shear modulus, so muscle, fascia and fat keep their
// ratio of stiffness along and across: at small strain and constant volume the fibres make a uniaxial
// stretch along them 1 + 4k₁/(3μ) times as stiff as across, and Song's ratio of 1.89 is k₁ = 0.67 μ.
#include <cstdint>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {

/// The circumferential unit direction (world, rest) of every tetrahedron with `fibrous[t]`, zero for
/// the others and where the tetrahedron's centre lies on the body's axis.
std::vector<Vec3> circumferential_fibres(const Mesh& m, const std::vector<uint8_t>& fibrous);

/// Fills m.tet_fibre, m.tet_fibre_k1_pa and m.fibre_k2: circumferential fibres in the tetrahedra marked
/// `fibrous`, with k₁ = k1_over_mu × μ_t (μ_t from tet_young_pa and tet_poisson) and k₂ = k2.
void assign_wall_fibres(Mesh& m, const std::vector<uint8_t>& fibrous, double k1_over_mu, double k2);

}  // namespace pneumo
