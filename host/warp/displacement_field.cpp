#include "warp/displacement_field.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pneumo {

DisplacementField pull_back_field(const std::string& device, const WarpMesh& mesh, const Role* roles,
                                  const WarpBox& box, const Geometry& output_grid) {
  if (output_grid.dims != box.dims) throw std::logic_error("pull_back_field: the output grid is not the box's");
  const Index3 dims = mesh.grid.dims;
  const int64_t n_work = mesh.grid.voxel_count();
  const std::size_t n_out = std::size_t(box.voxel_count());
  DisplacementField f;
  f.grid = output_grid;
  std::vector<double> delta_ijk(3 * n_out, 0.0);   // P − x in working-grid index units
  std::vector<WarpOutcome> outcome;
  std::vector<float> coordinate(static_cast<std::size_t>(n_work));
  WarpOptions opt;
  opt.gas_hu = 0.0f;   // unused: gas voxels get u = 0
  for (int a = 0; a < 3; ++a) {
    for (int64_t k = 0; k < dims[2]; ++k)
      for (int64_t j = 0; j < dims[1]; ++j)
        for (int64_t i = 0; i < dims[0]; ++i) {
          const int64_t ijk[3] = {i, j, k};
          coordinate[std::size_t(mesh.grid.linear_index(i, j, k))] = float(ijk[a]);
        }
    WarpSource src;
    src.ct_hu = coordinate.data();
    src.roles = roles;
    const WarpResult r = warp_on_device(device, mesh, src, box, opt);
    if (a == 0) {
      outcome = r.outcome;
      f.carried_voxels = r.carried_voxels, f.gas_voxels = r.gas_voxels, f.kept_voxels = r.kept_voxels;
    } else if (r.outcome != outcome) {
      throw std::logic_error("pull_back_field: the warp's outcomes differ between its passes");
    }
    for (int64_t k = 0; k < box.dims[2]; ++k)
      for (int64_t j = 0; j < box.dims[1]; ++j)
        for (int64_t i = 0; i < box.dims[0]; ++i) {
          const std::size_t n = std::size_t(i + box.dims[0] * (j + box.dims[1] * k));
          if (outcome[n] != WarpOutcome::Carried) continue;
          const double own[3] = {double(box.lo[0] + i), double(box.lo[1] + j), double(box.lo[2] + k)};
          // A source outside the working grid would read air (−1000): the warp's meshes lie inside it.
          if (!(r.ct_hu[n] > -1.0f))
            throw std::logic_error("pull_back_field: a carried voxel's source lies outside the working grid");
          delta_ijk[3 * n + std::size_t(a)] = double(r.ct_hu[n]) - own[a];
        }
  }
  // Index steps to world RAS millimetres (the direction's columns scaled by the spacing), then to LPS.
  const Mat3 to_ras = mesh.grid.direction * mesh.grid.spacing_mm.asDiagonal();
  f.u_lps_mm.assign(3 * n_out, 0.0f);
  for (std::size_t n = 0; n < n_out; ++n) {
    const Vec3 ras = to_ras * Vec3(delta_ijk[3 * n], delta_ijk[3 * n + 1], delta_ijk[3 * n + 2]);
    const Vec3 lps(-ras[0], -ras[1], ras[2]);
    for (int c = 0; c < 3; ++c) f.u_lps_mm[3 * n + std::size_t(c)] = float(lps[c]);
    f.max_norm_mm = std::max(f.max_norm_mm, lps.norm());
  }
  return f;
}

}  // namespace pneumo
