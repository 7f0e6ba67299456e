#pragma once
// Exact Euclidean distance transform in millimetres on an anisotropic grid (Felzenszwalb &
// Huttenlocher 2012, "Distance transforms of sampled functions": the 1-D lower envelope of
// parabolas along each axis in turn, with the axis' spacing), O(voxels).
#include <cstdint>
#include <vector>

#include "core/geometry.h"

namespace pneumo {

/// For every voxel: the distance (mm) from its centre to the nearest voxel centre with
/// inside == 0; 0 on those voxels. Only voxels of the grid count: beyond its faces is neither
/// inside nor outside, so a body cut by the field of view gets no false skin there; a voxel with no
/// outside voxel anywhere in the grid gets +infinity. Spacing per axis is respected; directions are
/// taken as orthogonal (true of every CT we read: oblique shears are not supported here).
std::vector<float> distance_to_outside_mm(const std::vector<uint8_t>& inside, const Geometry& g);

}  // namespace pneumo
