#pragma once
// The largest 6-connected component of a binary mask, found on runs along i (a run-length union-
// find): memory grows with the number of runs, not voxels, so a 512×512×400 body costs a few MB.
#include <cstdint>
#include <vector>

#include "core/geometry.h"

namespace pneumo {

/// Clears every voxel of `mask` (0/1, i fastest, dims `dims`) outside its largest 6-connected
/// component. Returns the voxel count of that component (0 for an empty mask).
int64_t keep_largest_component(std::vector<uint8_t>& mask, const Index3& dims);

}  // namespace pneumo
