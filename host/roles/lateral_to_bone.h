#pragma once
// Deep tissue lateral to bone is not in the abdominal cavity: around the hip joints and outside the
// iliac wings and pubic rami lie the gluteal, hip and thigh muscles. The automatic rules would call
// that tissue viscera (it is inside the body and deeper than the wall shell); this rule holds it
// fixed instead.
#include <cstdint>
#include <vector>

#include "anatomy/anatomical_axes.h"
#include "anatomy/body_mask.h"
#include "domain/types.h"

namespace pneumo {

struct LateralToBoneRules {
  // Bone nearer the midline than this does not count: the pubic symphysis, the spine, and a
  // calcified aorta or iliac artery near the midline must not cut the abdomen in two.
  double min_offset_mm = 40.0;
};

/// In each axial slice and each row along the lateral axis, the voxels for which `candidate` is 1
/// that lie further from the slice's centroid than the outermost bone voxel (bone[v] = 1) on the
/// same side, at least min_offset_mm out. Returns 1 for those voxels, 0 elsewhere.
std::vector<uint8_t> lateral_to_bone(const std::vector<uint8_t>& bone, const std::vector<uint8_t>& candidate,
                                     const std::vector<SliceCentre>& centres, const SliceFrame& f,
                                     const LateralToBoneRules& rules = {});

}  // namespace pneumo
