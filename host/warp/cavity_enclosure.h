#pragma once
// Rule 5 of the warp (warp.h): gas that no tetrahedron covers and that was outside the body at rest.
//
// Rule 4 calls an uncovered voxel gas only where a mesh was before or is after the deformation. When
// the wall rises by more than its own thickness, its inner face ends up in front of where the skin
// was: between the two lies space that was outside the body at rest, that no deformed tetrahedron
// covers, and that rule 4 therefore left as the air that was there, labelled "outside", although it
// is enclosed by the inflated wall. How much of it rule 4 missed depended on the cube size (coarse
// wall cubes reach into the viscera and their refusing tetrahedra covered part of it), so the warped
// cavity did not converge as cubes shrank (docs/fidelity.md §4).
//
// The rule: an output voxel that rule 4 kept (no tetrahedron covers it, no mesh was there) and that
// was outside the body at rest is gas when, after the deformation, it is enclosed in its axial slice,
// i.e. not 4-connected to the slice's border through such voxels. "Outside the body at rest" is what
// rule 4 would have kept at rest (no mesh there) with the role `other`, reachable from the slice's
// border through such voxels then: tissue the roles call `other` inside the body (a label no role
// lists) never becomes gas, and a zero displacement changes nothing. Per axial slice, as the body
// mask's holes are filled (anatomy/body_mask.h): one slice's chink cannot open a whole cavity.
#include <cstdint>

#include "domain/types.h"
#include "warp/warp.h"

namespace pneumo {

/// Applies rule 5 to a warp's result `r` over `box` of the working grid `mesh.grid`, whose roles
/// are `src.roles`. Returns the voxels that became gas (HU opt.gas_hu, label opt.cavity_label).
int64_t enclose_cavity(WarpResult& r, const WarpMesh& mesh, const WarpSource& src, const WarpBox& box,
                       const WarpOptions& opt);

}  // namespace pneumo
