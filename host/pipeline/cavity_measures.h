#pragma once
// Measures of where the gas went and how the viscera moved, for the fidelity targets of the issue
// "A human answer" (docs/fidelity.md): gas in front of an extraperitoneal organ, and the viscera's
// posterior motion where the gas pushes them.
#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "mesh/mesh.h"

namespace pneumo {

/// Gas voxels (== gas_label) lying anterior to a voxel of one of `ids` in the same axial column
/// (same slice, same lateral index; roles/anatomical_axes.h): on the deformed labels with the
/// bladder's id, the prevesical space, where no gas should open (it is extraperitoneal). Counts
/// voxels; 0 when no listed id is present.
int64_t gas_voxels_anterior_to(const std::vector<uint16_t>& labels, const Geometry& g, uint16_t gas_label,
                               const std::vector<int>& ids);

/// The mean posterior displacement (mm, positive = towards the back) of the viscera nodes in the
/// anterior half of the viscera's rest extent from back to front (world y, RAS): where the gas lies
/// on them and patients' bowel moves dorsally.
double mean_posterior_motion_of_anterior_viscera_mm(const Mesh& m, const std::vector<Vec3>& x);

}  // namespace pneumo
