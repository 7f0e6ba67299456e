#pragma once
// The warp's map as a dense displacement field: the form in which ITK, ANTs and 3D Slicer apply a
// deformation to any other image (a contrast phase, a segmentation, a dose map).
//
// For each output voxel centre x the warp reads the source at a point P(x) (warp.h, rule 1). The field
// holds u(x) = P(x) − x in millimetres: a pull-back (backward) field, the direction ITK's
// DisplacementFieldTransform and ResampleImageFilter use, output(x) = input(x + u(x)). Components are
// in ITK's LPS frame (x to the patient's left, y posterior, z superior), the grid is the output grid.
//
// How it is found: trilinear interpolation reproduces a function linear in the voxel index exactly,
// so warping the three images c_a(voxel) = its index along axis a gives P(x) at every carried voxel,
// by the same warp on the same device, acceptance and tie-breaks included: nothing to drift from the
// warp the CT went through. The samples are float32 (index coordinates below 2^15: error < 2^-9
// voxel), and where P lies past the outermost voxel centre of the working grid (its last half voxel,
// in the air the roles pad with) the sampling clamps, so there the component may be short by up to
// half a voxel.
//
// Voxels no tetrahedron covers (kept) have u = 0. Gas voxels have no source (new space): u = 0 there
// too, and the deformed label map marks them with the cavity label, so a field applied to another
// image leaves that image's own value in the cavity, where the caller puts gas (−1000 HU).
#include <cstdint>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "domain/types.h"
#include "warp/warp.h"

namespace pneumo {

struct DisplacementField {
  Geometry grid;                 // the output grid (the box of the working grid), world RAS as every Geometry
  std::vector<float> u_lps_mm;   // 3 per voxel, (x, y, z) interleaved, voxels i fastest
  int64_t carried_voxels = 0, gas_voxels = 0, kept_voxels = 0;
  double max_norm_mm = 0.0;      // the largest |u|
};

/// The pull-back field of the warp of `mesh` over `box` (acceptance by `roles`, working-grid voxels),
/// run on `device` as warp_on_device. `output_grid` is the box's geometry.
DisplacementField pull_back_field(const std::string& device, const WarpMesh& mesh, const Role* roles,
                                  const WarpBox& box, const Geometry& output_grid);

}  // namespace pneumo
