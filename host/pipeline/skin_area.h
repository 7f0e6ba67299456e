#pragma once
// The wall's skin before and after the inflation: Song et al. 2006 (Surg Endosc, 18 patients,
// 12 mmHg) measured the abdominal wall's area growing by
// 15 %. The skin here is every face between a wall voxel and the air outside the body within the CT's
// own box (faces toward the padding around it, where the CT cut the body, are no skin; nor are faces
// toward tissue left out inside the body); each face's corners are carried through the deformation
// and its deformed area is that of the two triangles they span.
#include <cstdint>
#include <functional>

#include <vector>

#include "core/geometry.h"
#include "mesh/mesh.h"

namespace pneumo {

struct SkinArea {
  double rest_mm2 = 0.0, deformed_mm2 = 0.0;
  int64_t faces = 0;
  int64_t corners_not_carried = 0;   // corners the map left in place (outside every tetrahedron)
  double change() const { return rest_mm2 > 0.0 ? deformed_mm2 / rest_mm2 - 1.0 : 0.0; }
};

/// A point of the original frame (world mm) carried to the deformed one; false where it is not.
using CarryFn = std::function<bool(const Vec3& original_mm, Vec3& deformed_mm)>;

/// The skin of the wall voxels of `roles` whose neighbour is outside `body` (one per voxel; 1 inside,
/// anatomy/body_mask.h) and within the CT's box (VoxelRoles::ct_first/ct_last), at rest and carried by
/// `carry`.
SkinArea wall_skin_area(const VoxelRoles& roles, const std::vector<uint8_t>& body, const CarryFn& carry);

}  // namespace pneumo
