#pragma once
// The body for the automatic roles: HU above a threshold, its largest 6-connected part (the table
// and anything else not touching the patient drop out), holes filled slice by slice (axial) so gas
// in bowel and aerated lung count as inside.
#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "anatomy/anatomical_axes.h"

namespace pneumo {

/// 1 inside the body, 0 outside; `hu` on grid `g`, i fastest.
std::vector<uint8_t> body_mask(const float* hu, const Geometry& g, double threshold_hu);

/// Fills, in each axial slice, the background not 4-connected to the slice's border. (4-connected
/// background is the complement of 8-connected foreground: a diagonal chink lets no air in.)
void fill_holes_per_axial_slice(std::vector<uint8_t>& mask, const SliceFrame& f);

/// Centroid of the body in each axial slice, in voxel index units along the lateral axis and in
/// anteriority (SliceFrame::ant) along the antero-posterior axis; count 0 where a slice is empty.
struct SliceCentre {
  double lat = 0.0, ant = 0.0;
  int64_t count = 0;
};
std::vector<SliceCentre> body_centres(const std::vector<uint8_t>& mask, const SliceFrame& f);

}  // namespace pneumo
