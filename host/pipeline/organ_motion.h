#pragma once
// Where each labelled structure went (issue "The abdomen expands as patients' does", item 5): its
// volume at rest and deformed, and the shift of its centroid in world millimetres (RAS), from the
// label map before and after the warp, so the figures are those of the images a user opens. The
// deformed map is the warp's nearest-label image (warp.h): a structure's deformed volume counts the
// voxels whose centre the deformation carries into it, so its change is the tissue's volume change to
// within a voxel layer over its surface. Compared in docs/fidelity.md with patients' organ motion
// (Nainamalai 2025: the liver 45 mm cranially, −12 % of its volume, at 12 mmHg).
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/geometry.h"

namespace pneumo {

struct OrganMotion {
  int label = 0;
  std::string name;              // from the label names; empty where none
  double volume_ml = 0.0;        // at rest
  double volume_change = 0.0;    // deformed / rest − 1
  Vec3 shift_mm = Vec3::Zero();  // deformed centroid − rest centroid, world RAS
};

/// The labels `ids` of `rest` (on `rest_grid`) of at least `min_ml`, except 0 and `skip` (the cavity's
/// label), against `deformed` (on `deformed_grid`), in increasing label order; none when `ids` is empty.
std::vector<OrganMotion> organ_motion(const std::vector<uint16_t>& rest, const Geometry& rest_grid,
                                      const std::vector<uint16_t>& deformed, const Geometry& deformed_grid,
                                      uint16_t skip, const std::map<int, std::string>& names,
                                      const std::vector<int>& ids, double min_ml = 1.0);

}  // namespace pneumo
