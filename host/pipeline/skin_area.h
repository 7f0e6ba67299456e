#pragma once
// The wall's skin before and after the inflation (issue "The abdomen expands as patients' does", item
// 5): Song et al. 2006 (Surg Endosc, 18 patients, 12 mmHg) measured the abdominal wall's area growing by
// 15 %. The skin here is every face between a wall voxel and air inside the CT's own box (faces toward
// the padding around it, where the CT cut the body, are no skin); each face's corners are carried
// through the deformation and its deformed area is that of the two triangles they span.
#include <cstdint>
#include <functional>

#include "core/geometry.h"
#include "domain/types.h"

namespace pneumo {

struct SkinArea {
  double rest_mm2 = 0.0, deformed_mm2 = 0.0;
  int64_t faces = 0;
  int64_t corners_not_carried = 0;   // corners the map left in place (outside every tetrahedron)
  double change() const { return rest_mm2 > 0.0 ? deformed_mm2 / rest_mm2 - 1.0 : 0.0; }
};

/// A point of the original frame (world mm) carried to the deformed one; false where it is not.
using CarryFn = std::function<bool(const Vec3& original_mm, Vec3& deformed_mm)>;

/// The skin of the wall voxels of `role` (one per voxel of `g`) whose air neighbour lies within the
/// CT's box `ct_first`..`ct_last` (a last of -1: the grid's last), at rest and carried by `carry`.
SkinArea wall_skin_area(const Geometry& g, const Role* role, const Index3& ct_first, const Index3& ct_last,
                        const CarryFn& carry);

}  // namespace pneumo
