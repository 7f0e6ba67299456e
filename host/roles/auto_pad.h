#pragma once
// Room for the wall to rise, found on the CT instead of asked of the user. A 12 mmHg abdomen rises
// 30–60 mm anteriorly (docs/fidelity.md: 44 mm on the example CT; Song et al. 2006) and bulges
// laterally; a clinical CT is often reconstructed with the skin a few millimetres from the edge of
// its field of view. Where a scene leaves roles.pad_anterior_mm or pad_lateral_mm unset, the side
// is padded by kAutoPadMm when the body comes closer than that to the grid's edge on it, and not at
// all otherwise. One fixed amount, not a top-up to it: the anatomy then sits at the same place in
// the padded grid's lattice (a whole number of voxels) whatever air the scan had.
#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "roles/pad.h"
#include "roles/role_rules.h"

namespace pneumo {

inline constexpr double kAutoPadMm = 60.0;

/// The body's distance to the grid's edge on each side (mm): anterior, the patient's right and left.
/// `body` as the automatic roles see it (anatomy/body_mask.h), on grid `g`.
struct BodyClearance {
  double anterior_mm = 0.0, right_mm = 0.0, left_mm = 0.0;
};
BodyClearance body_clearance(const std::vector<uint8_t>& body, const Geometry& g);

/// The padding of a case: the scene's where it gives one, else, with roles.source "auto", kAutoPadMm on
/// a side whose clearance is below it (lateral: either side); "labels" describes every voxel itself,
/// its air included (the phantoms), and gets none. `body` is on the CT's own grid (may be null when
/// nothing is to be found: both sides given, or source "labels").
PadMm resolved_pad_mm(const RoleRules& rules, const std::vector<uint8_t>* body, const Geometry& g);

}  // namespace pneumo
