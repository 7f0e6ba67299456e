#include "warp/warp_mesh.h"

#include <cmath>
#include <stdexcept>

#include "core/units.h"

namespace pneumo {

bool WarpMesh::in_rest_space(int64_t i, int64_t j, int64_t k) const {
  if (i < 0 || j < 0 || k < 0) return false;
  const int64_t L = cube_voxels;
  const int64_t a = i / L, b = j / L, c = k / L;
  if (a >= cubes[0] || b >= cubes[1] || c >= cubes[2]) return false;
  return cube_meshed[std::size_t(a + cubes[0] * (b + cubes[1] * c))] != 0;
}

WarpMesh make_warp_mesh(const Mesh& mesh, const std::vector<Vec3>& displacement_m) {
  if (int64_t(displacement_m.size()) != mesh.node_count())
    throw std::invalid_argument("make_warp_mesh: " + std::to_string(displacement_m.size()) + " displacements for " +
                                std::to_string(mesh.node_count()) + " nodes");
  WarpMesh w;
  w.grid = mesh.grid;
  // World mm = origin + A·ijk with A = direction·diag(spacing); displacements map through A⁻¹ alone.
  const Mat3 a_inv = (mesh.grid.direction * mesh.grid.spacing_mm.asDiagonal()).inverse();
  const int64_t n = mesh.node_count();
  w.rest_ijk.resize(n);
  w.disp_ijk.resize(n);
  for (int64_t i = 0; i < n; ++i) {
    w.rest_ijk[i] = mesh.grid.to_index(units::m_to_mm(1.0) * mesh.rest_m[i]);
    w.disp_ijk[i] = a_inv * (units::m_to_mm(1.0) * displacement_m[i]);
  }
  w.tets = mesh.tets;
  w.tet_part = mesh.tet_part;
  w.cube_voxels = mesh.cube_voxels;
  w.cubes = mesh.cubes;
  w.cube_meshed.assign(std::size_t(mesh.cubes[0] * mesh.cubes[1] * mesh.cubes[2]), 0);
  for (int64_t q : mesh.tet_cube) w.cube_meshed[std::size_t(q)] = 1;
  return w;
}

bool warp_tet_degenerate(const WarpMesh& m, int64_t tet) {
  const auto& t = m.tets[std::size_t(tet)];
  const Vec3 x0 = m.deformed_ijk(t[0]);
  Mat3 e;
  e << m.deformed_ijk(t[1]) - x0, m.deformed_ijk(t[2]) - x0, m.deformed_ijk(t[3]) - x0;
  const double scale = std::max({e.col(0).norm(), e.col(1).norm(), e.col(2).norm()});
  const double det = e.determinant();
  return !std::isfinite(det) || !(scale > 0.0) || std::abs(det) < 1e-9 * scale * scale * scale;
}

}  // namespace pneumo
