#pragma once
// How far the diaphragm rose (docs/fidelity.md, "The diaphragm"). The gas pushes
// the diaphragm into the chest where the lungs give way (roles.compliant_lungs); the lungs' base is
// the diaphragm's thoracic face. Per axial column of the CT's own box that holds lung over tissue,
// the lowest lung voxel's lower face centre is carried through the deformation and its cranial
// displacement taken: the median over those columns says how the diaphragm as a whole moved, the
// 95th percentile how far its domes rose. The lungs are those the CT's density finds
// (anatomy/thorax.h: aerated parts of lung size and density, not bowel gas), whatever their role;
// with fixed lungs (roles.compliant_lungs false) the diaphragm stays.
#include <cstdint>
#include <functional>
#include <vector>

#include "core/geometry.h"
#include "mesh/mesh.h"
#include "pipeline/skin_area.h"

namespace pneumo {

struct DiaphragmMotion {
  int64_t columns = 0;             // columns with lung over tissue in the CT's box
  int64_t not_carried = 0;         // of them, points the deformation did not carry (left out)
  double median_cranial_mm = 0.0;  // median cranial displacement of the lungs' base
  double dome_cranial_mm = 0.0;    // its 95th percentile
};

/// The diaphragm's thoracic face on `roles`: under `lungs` (one per voxel, 1 = lung), over body
/// voxels (`body`); each face centre carried by `carry` (original → deformed, world mm).
DiaphragmMotion diaphragm_motion(const VoxelRoles& roles, const std::vector<uint8_t>& body,
                                 const std::vector<uint8_t>& lungs, const CarryFn& carry);

}  // namespace pneumo
