#pragma once
// What a scan covers, in anatomical words: where its first and last axial slices cut the body and
// through which structures, whether the diaphragm's dome and the pelvis are in view, and whether the
// field of view cuts the wall at the sides or in front. A planner reads it before trusting the
// answer near a cut: the solver leaves a cut face free (docs/roles.md, "Limits"), so a scan cut
// through the liver or above the pelvis has a wall that can open there like a flap.
#include <map>
#include <string>
#include <vector>

#include "roles/roles.h"

namespace pneumo {

struct CutFace {
  bool cuts_body = false;               // the body's section there is at least kCutFraction of its widest
  double body_fraction = 0.0;           // body area in that slice / the widest slice's
  std::vector<std::string> structures;  // named structures holding ≥ kStructureShare of that slice, largest first
};

inline constexpr double kCutFraction = 0.2;
inline constexpr double kStructureShare = 0.02;   // of a cut slice's body, to be named there

struct ScanCoverage {
  CutFace top, bottom;                  // the CT's own first and last slices towards the head and the feet
  bool lungs_in_view = false, pelvis_in_view = false;   // by name: a lung; a hip, sacrum or bladder
  bool wall_cut_laterally = false, wall_cut_anteriorly = false;   // wall voxels on the CT's own edge
  std::string summary;                  // one sentence
  std::vector<std::string> warnings;    // what is missing, and what that means for the answer
};

/// The coverage of the CT inside `rv` (its padding excluded); `names` names the label ids (may be empty).
ScanCoverage scan_coverage(const RoleVolume& rv, const std::map<int, std::string>& names);

}  // namespace pneumo
