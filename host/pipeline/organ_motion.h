#pragma once
// Where each labelled structure went: its
// volume at rest and deformed, and the shift of its centroid in world millimetres (RAS), from the
// label map before and after the warp, so the figures are those of the images a user opens. The
// deformed map is the warp's nearest-label image (warp.h): a structure's deformed volume counts the
// voxels whose centre the deformation carries into it, so its change is the tissue's volume change to
// within a voxel layer over its surface. Compared in docs/fidelity.md with patients' organ motion
// (Nainamalai 2025: the liver 45 mm cranially, −12 % of its volume, at 12 mmHg).
//
// The tissue's own volume change comes beside it, from the deformation rather than the images: the
// mean over the structure's voxels at rest of J − 1, J the volume ratio of the tetrahedron that
// carries the voxel's centre (1 where none does: outside the meshes nothing moves). The image's
// figure adds the warp's resampling at the structure's surface, a few per cent on a small organ
// (docs/fidelity.md, "The viscera's volume"); the tissue's is what the material gives.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/geometry.h"

namespace pneumo {

struct OrganMotion {
  int label = 0;
  std::string name;              // from the label names; empty where none
  double volume_ml = 0.0;        // at rest
  double volume_change = 0.0;    // deformed / rest − 1, in the label images
  std::optional<double> tissue_volume_change;   // the mean of J − 1 over its voxels at rest, where a J is given
  Vec3 shift_mm = Vec3::Zero();  // deformed centroid − rest centroid, world RAS
};

/// The volume ratio J of the deformation at rest voxel `voxel` (linear index on the rest grid), whose
/// centre is `rest_mm` (world); none where nothing moves the voxel (outside the meshes, fixed tissue).
using JacobianAtFn = std::function<std::optional<double>(int64_t voxel, const Vec3& rest_mm)>;

/// The labels `ids` of `rest` (on `rest_grid`) of at least `min_ml`, except 0 and `skip` (the cavity's
/// label), against `deformed` (on `deformed_grid`), in increasing label order; none when `ids` is empty.
std::vector<OrganMotion> organ_motion(const std::vector<uint16_t>& rest, const Geometry& rest_grid,
                                      const std::vector<uint16_t>& deformed, const Geometry& deformed_grid,
                                      uint16_t skip, const std::map<int, std::string>& names,
                                      const std::vector<int>& ids, double min_ml = 1.0,
                                      const JacobianAtFn& jacobian = nullptr);

}  // namespace pneumo
