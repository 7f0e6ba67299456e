#pragma once
// Gas pockets too small to be the cavity. The warp calls gas every voxel inside the meshes that no
// accepting tetrahedron covers (method.md §7). Where the wall's and the viscera's tetrahedra leave
// a voxel or a few uncovered between them, far from the cavity, that is a crack of the
// discretisation, not CO2: an isolated pocket of a few voxels cannot be insufflated. Pieces below a
// size floor are therefore filled from their surroundings.
#include <cstdint>

#include "core/geometry.h"
#include "warp/warp.h"

namespace pneumo {

struct SpeckFill {
  int64_t pieces = 0, voxels = 0;   // the pieces filled and their voxels
};

/// Gas pieces (6-connected, outcome Gas) of fewer than `min_voxels` voxels: each of their voxels takes
/// the HU and label of a 6-neighbour that is not gas, filled inward from the piece's surface one layer
/// per pass (from the previous pass's values, in index order: deterministic), and counts as carried.
/// `r` covers a box of `dims` voxels. Pieces touching nothing but gas and the box's edge stay.
SpeckFill fill_cavity_specks(WarpResult& r, const Index3& dims, int64_t min_voxels);

}  // namespace pneumo
