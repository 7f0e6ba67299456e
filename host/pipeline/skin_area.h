#pragma once
// The wall's skin before and after the inflation: Song et al. 2006 (Surg Endosc, 18 patients,
// 12 mmHg) measured the abdominal wall's area growing by
// 15 %. The skin here is every face between a wall voxel and the air outside the body within the CT's
// own box (faces toward the padding around it, where the CT cut the body, are no skin; nor are faces
// toward tissue left out inside the body); each face's corners are carried through the deformation
// and its deformed area is that of the two triangles they span.
//
// Song measured the skin a camera above the supine patient sees: a remote motion-analysis system
// tracked the anterior abdominal wall. The whole skin of the wall also holds the flanks and, where the
// roles make it wall, the chest and the hips, which the gas hardly moves, so it dilutes the growth. The
// anterior skin is the part of it over the peritoneal cavity and in front: its voxel's ray towards the
// back meets viscera before bone (not the ribs, the pelvis or the thighs), and its face lies within
// kAnteriorSectorDeg of straight ahead seen from the body's axis in its axial slice (the centroid of the
// body's voxels in that slice): 60° reaches about the anterior axillary lines. docs/fidelity.md gives
// the figure at 45° and 90° too.
#include <cstdint>
#include <functional>

#include <vector>

#include "core/geometry.h"
#include "mesh/mesh.h"

namespace pneumo {

inline constexpr double kAnteriorSectorDeg = 60.0;

struct SkinArea {
  double rest_mm2 = 0.0, deformed_mm2 = 0.0;
  double anterior_rest_mm2 = 0.0, anterior_deformed_mm2 = 0.0;   // of the faces within the anterior sector
  int64_t faces = 0;
  int64_t corners_not_carried = 0;   // corners the map left in place (outside every tetrahedron)
  double change() const { return rest_mm2 > 0.0 ? deformed_mm2 / rest_mm2 - 1.0 : 0.0; }
  double anterior_change() const { return anterior_rest_mm2 > 0.0 ? anterior_deformed_mm2 / anterior_rest_mm2 - 1.0 : 0.0; }
};

/// A point of the original frame (world mm) carried to the deformed one; false where it is not.
using CarryFn = std::function<bool(const Vec3& original_mm, Vec3& deformed_mm)>;

/// The skin of the wall voxels of `roles` whose neighbour is outside `body` (one per voxel; 1 inside,
/// anatomy/body_mask.h) and within the CT's box (VoxelRoles::ct_first/ct_last), at rest and carried by
/// `carry`; the anterior skin's faces are those whose centre lies within `anterior_sector_deg` of world
/// anterior (+y, RAS) seen from the body's axis in the face's slice, of a voxel over the viscera.
SkinArea wall_skin_area(const VoxelRoles& roles, const std::vector<uint8_t>& body, const CarryFn& carry,
                        double anterior_sector_deg = kAnteriorSectorDeg);

}  // namespace pneumo
