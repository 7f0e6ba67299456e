#pragma once
// Automatic roles (roles.source = "auto", method.md §2 option) for a CT whose abdominal wall is not
// labelled. The rules, in order of precedence (the first that applies decides):
//   1. labels (auto_use_labels, a label map given): a voxel whose id (not 0) is in a role list keeps
//      that role, wherever it is;
//   2. outside the body → other. Body = HU > auto_body_threshold_hu, largest 6-connected part,
//      holes filled per axial slice (body_mask.h);
//   3. HU > auto_bone_threshold_hu → fixed (bone);
//   3b. with auto_thorax: the chest above the diaphragm (anatomy/thorax.h: the lungs by density or
//      by their labels, the diaphragm's surface under them, the heart and mediastinum between them):
//      the rest of it deeper than auto_wall_thickness_mm → fixed; the lungs with their vessels
//      (Thorax::lung_tissue) → wall with compliant_lungs (the diaphragm rises into them), else fixed;
//   4. the back: behind the anterior surface of the vertebral column in the slice → fixed
//      (back_region.h; the column is found from rules 1 and 3's fixed voxels near the midline);
//   5. the shell: within auto_wall_thickness_mm of the body's surface (3-D Euclidean distance in mm,
//      spacing respected) → wall where the direction from the slice's body centroid is within
//      auto_wall_max_angle_deg of anterior, fixed beyond (the back lying on the table);
//   5b. with auto_use_labels and a label map: undecided tissue anterior to a voxel of
//      auto_prevesical_labels in the same axial column (same slice, same lateral position) → wall:
//      the space of Retzius between the bladder and the wall is extraperitoneal, so no gas opens
//      in front of the bladder (docs/fidelity.md). Where an organ of viscera_labels lies in front
//      of the bladder in the column (5b and 6b alike), the wall starts at that organ's front: the
//      peritoneum lies in front of the bladder at that level, and the tissue behind the organ is on
//      its peritoneal side;
//   5c. with auto_thorax: undecided tissue within auto_diaphragm_thickness_mm of 3b's chest → wall:
//      the diaphragm, so the gas opens under it, never beside a lung or the heart; with
//      compliant_lungs, labelled viscera within that distance of a lung or the heart too;
//   6. deeper tissue lateral to bone that is at least 40 mm from the midline (hip joints, iliac
//      wings, pubic rami: the gluteal, hip and thigh muscles) → fixed (lateral_to_bone.h);
//   6b. with auto_use_labels and a label map: in the axial slices from the top (dome) of the
//      auto_prevesical_labels down, undecided tissue anterior to the organ's back in that slice
//      (below its lowest slice, its back there) → wall. The peritoneum covers the bladder's dome
//      and reflects from it onto the anterior wall; below that only the pouch behind the bladder is
//      peritoneal: the prevesical and paravesical spaces and the groin in front of the hips are
//      extraperitoneal (on the real CT gas opened there in pockets apart from the cavity);
//   7. everything else in the body → viscera.
// Limits, stated so nobody trusts more than this:
//   - The wall is a shell of uniform thickness, not the real skin/fat/muscle layers: where the wall
//     is thinner, unlabelled tissue just behind it (mesenteric fat, unlabelled bowel) becomes wall;
//     where it is thicker (obesity), its inner muscle layer becomes viscera. Organ labels protect
//     the organs they cover (rule 1 first).
//   - Bone is HU only: contrast-filled vessels or bowel, calcifications and metal above the
//     threshold become fixed unless a label says otherwise.
//   - One body: a second body part not touching the largest one (an arm beside the torso) is other.
//     A table touching the body stays in it and ends up fixed (it is behind the spine).
//   - The back rule is per axial slice and assumes a supine patient with the spine posterior;
//     without labels, posterior parts of retroperitoneal organs (kidneys, ascending and descending
//     colon) behind the front of the column become fixed.
//   - The angle is measured around the slice's centroid, so a very asymmetric section shifts the
//     wall's lateral limit.
//   - The diaphragm is a height field under the lungs (anatomy/thorax.h's limits); with no lung in
//     view (a scan that starts below the lung bases) there is no chest to hold, and what lies at the
//     top slice is decided by the other rules. The held chest continues the back rule's run from the
//     spine through the heart, as labelled lungs and heart do.
//   - Below the pelvic brim the rules are rough: without a bladder label (rule 6b), tissue in front
//     of the pubic rami in rows without bone (the inguinal region, the front of the thighs) becomes
//     viscera.
#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "domain/types.h"
#include "roles/role_rules.h"

namespace pneumo {

/// Roles on grid `g` from `hu` (HU, i fastest) and, when not null, `label` on the same grid. `body`, when
/// given, is body_mask's result on this grid (assign_roles finds it once for the padding too).
std::vector<Role> auto_roles(const RoleRules& rules, const Geometry& g, const float* hu, const uint16_t* label,
                             const std::vector<uint8_t>* body = nullptr);

}  // namespace pneumo
