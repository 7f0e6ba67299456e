#pragma once
// Measures of where the gas went and how the viscera moved, for the fidelity targets of
// docs/fidelity.md §2 and §5: gas in front of an extraperitoneal organ, and the viscera's
// posterior motion where the gas pushes them.
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "core/geometry.h"
#include "mesh/mesh.h"

namespace pneumo {

/// Where the deformed frame's organ lay before the deformation: the label map at rest on its grid,
/// and the map of a deformed point (world mm) to where its tissue was (nullopt: no tetrahedron
/// carries it; warp/point_map.h).
struct RestColumns {
  const uint16_t* labels = nullptr;
  Geometry grid;
  std::function<std::optional<Vec3>(const Vec3& deformed_mm)> to_rest;
};

/// Gas voxels (== gas_label) lying anterior to a voxel of one of `ids` in the same axial column
/// (same slice, same lateral index; anatomy/anatomical_axes.h): on the deformed labels with the
/// bladder's id, gas in front of the bladder. Counts voxels; 0 when no listed id is present.
/// With `stop_ids` (the intraperitoneal organs), the column is followed forward from the organ's
/// front only until a voxel of one of them: gas beyond a bowel loop that lies in front of the
/// bladder's upper part is in the peritoneal cavity.
/// With `rest` as well, what remains is the gas in the prevesical space (the space of Retzius,
/// extraperitoneal), where none should open: each column's floor (the voxel behind its first gas
/// voxel, between the gas and the organ) is traced to rest, and where a voxel of `stop_ids` lay
/// within one voxel of it there, the column does not count. Its gas opened on the face an
/// intraperitoneal organ covered: the peritoneum over the bladder's dome, where a bowel loop lay and
/// left as the wall rose (the supravesical fossa). In the space of Retzius no intraperitoneal organ
/// touches the tissue in front of the bladder, so gas there counts, and so does gas whose floor no
/// tetrahedron carries.
int64_t gas_voxels_anterior_to(const std::vector<uint16_t>& labels, const Geometry& g, uint16_t gas_label,
                               const std::vector<int>& ids, const std::vector<int>& stop_ids = {},
                               const RestColumns* rest = nullptr);

/// The mean posterior displacement (mm, positive = towards the back) of the viscera nodes in the
/// anterior half of the viscera's rest extent from back to front (world y, RAS): where the gas lies
/// on them and patients' bowel moves dorsally.
double mean_posterior_motion_of_anterior_viscera_mm(const Mesh& m, const std::vector<Vec3>& x);

}  // namespace pneumo
