#pragma once
// The exact Euclidean distance (mm) from every voxel to the nearest voxel of a mask, on a grid with
// its own spacing along each axis: what the port ranking reads as a path's clearance from organs
// and vessels (plan/port_ranking.h).
//
// Felzenszwalb & Huttenlocher's separable transform (Theory of Computing 8, 2012: "Distance
// Transforms of Sampled Functions"): the squared distance is a minimum of parabolas, taken along one
// axis at a time by their lower envelope, exact and linear in the voxel count. Written here because
// none of the project's libraries offers it (ITK would be a dependency for one function).
#include <cstdint>
#include <vector>

#include "core/geometry.h"

namespace pneumo {

/// For each voxel (i fastest), the distance in mm from its centre to the nearest centre of a voxel
/// with mask != 0 (0 inside the mask), measured in index space scaled by the spacing, which is the
/// world distance for the orthogonal grids pneumo reads. +infinity everywhere when the mask is empty.
std::vector<float> distance_to_mask_mm(const std::vector<uint8_t>& mask, const Geometry& g);

}  // namespace pneumo
