#include "warp/cavity_enclosure.h"

#include <vector>

#include "anatomy/anatomical_axes.h"
#include "anatomy/body_mask.h"

namespace pneumo {

int64_t enclose_cavity(WarpResult& r, const WarpMesh& mesh, const WarpSource& src, const WarpBox& box,
                       const WarpOptions& opt) {
  const int64_t n = box.voxel_count();
  if (int64_t(r.outcome.size()) != n || src.roles == nullptr) return 0;
  Geometry box_grid = mesh.grid;   // the box's axes are the working grid's
  box_grid.dims = box.dims;
  const SliceFrame frame = slice_frame(box_grid);
  // At rest, 0 where rule 4 would keep the voxel as it is (no mesh there) and the roles call it
  // `other`, 1 elsewhere; filling the holes leaves 0 on what reaches the border only. Zero
  // displacement therefore changes nothing: the same voxels are kept, and they reach it the same way.
  // Row by row: 10⁸ voxels, whose (i, j, k) the loops give instead of three divisions each.
  std::vector<uint8_t> inside_at_rest(static_cast<std::size_t>(n));
  const int64_t nx = box.dims[0], ny = box.dims[1], nz = box.dims[2];
#pragma omp parallel for schedule(static)
  for (int64_t z = 0; z < nz; ++z)
    for (int64_t y = 0; y < ny; ++y) {
      const int64_t i0 = box.lo[0], j = box.lo[1] + y, k = box.lo[2] + z;
      const Role* role = src.roles + mesh.grid.linear_index(i0, j, k);
      uint8_t* inside = inside_at_rest.data() + nx * (y + ny * z);
      for (int64_t x = 0; x < nx; ++x) inside[x] = role[x] != Role::Other || mesh.in_rest_space(i0 + x, j, k);
    }
  fill_holes_per_axial_slice(inside_at_rest, frame);

  // After: 0 where a kept voxel was outside at rest (rule 4 left it as it was), 1 elsewhere.
  std::vector<uint8_t> blocked(static_cast<std::size_t>(n));
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v) blocked[v] = !(r.outcome[v] == WarpOutcome::Kept && !inside_at_rest[v]);
  fill_holes_per_axial_slice(blocked, frame);

  const bool labels = int64_t(r.labels.size()) == n;
  int64_t enclosed = 0;
#pragma omp parallel for schedule(static) reduction(+ : enclosed)
  for (int64_t v = 0; v < n; ++v) {
    if (r.outcome[v] != WarpOutcome::Kept || inside_at_rest[v] || !blocked[v]) continue;
    r.outcome[v] = WarpOutcome::Gas;
    r.ct_hu[v] = opt.gas_hu;
    if (labels) r.labels[v] = opt.cavity_label;
    ++enclosed;
  }
  r.kept_voxels -= enclosed;
  r.gas_voxels += enclosed;
  return enclosed;
}

}  // namespace pneumo
