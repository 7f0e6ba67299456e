#include "warp/warp_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/units.h"

namespace pneumo {

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

WarpMesh warp_mesh_on_grid(const WarpMesh& m, const Geometry& target) {
  WarpMesh w;
  w.grid = target;
  const Mat3 a_src = m.grid.direction * m.grid.spacing_mm.asDiagonal();
  const Mat3 a_tgt_inv = (target.direction * target.spacing_mm.asDiagonal()).inverse();
  const Mat3 lin = a_tgt_inv * a_src;   // source index units → target index units
  w.rest_ijk.resize(m.rest_ijk.size());
  w.disp_ijk.resize(m.disp_ijk.size());
  for (std::size_t n = 0; n < m.rest_ijk.size(); ++n) {
    w.rest_ijk[n] = target.to_index(m.grid.to_world(m.rest_ijk[n]));
    w.disp_ijk[n] = lin * m.disp_ijk[n];
  }
  w.tets = m.tets;
  w.tet_part = m.tet_part;
  w.cube_voxels = 1;
  w.cubes = {target.dims[0], target.dims[1], target.dims[2]};
  w.cube_meshed.assign(std::size_t(target.voxel_count()), 0);
  const Mat3 to_src = a_src.inverse() * (target.direction * target.spacing_mm.asDiagonal());
  const Vec3 src0 = m.grid.to_index(target.origin_mm);
  const CubeVoxels& L = m.cube_voxels;
  for (int64_t k = 0; k < target.dims[2]; ++k)
    for (int64_t j = 0; j < target.dims[1]; ++j)
      for (int64_t i = 0; i < target.dims[0]; ++i) {
        const Vec3 s = src0 + to_src * Vec3(double(i), double(j), double(k));
        // Cube a spans [aL₀ − ½, (a+1)L₀ − ½) in the source's index coordinates, and so on per axis.
        const double a = std::floor((s.x() + 0.5) / L[0]), b = std::floor((s.y() + 0.5) / L[1]),
                     c = std::floor((s.z() + 0.5) / L[2]);
        if (a < 0 || b < 0 || c < 0 || a >= double(m.cubes[0]) || b >= double(m.cubes[1]) || c >= double(m.cubes[2]))
          continue;
        w.cube_meshed[std::size_t(i + target.dims[0] * (j + target.dims[1] * k))] =
            m.cube_meshed[std::size_t(int64_t(a) + m.cubes[0] * (int64_t(b) + m.cubes[1] * int64_t(c)))];
      }
  return w;
}

void check_warp_mesh(const WarpMesh& m) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("warp mesh: " + what); };
  const int64_t nodes = int64_t(m.rest_ijk.size());
  if (int64_t(m.disp_ijk.size()) != nodes) fail("a displacement per node needed");
  if (m.tet_part.size() != m.tets.size()) fail("a part per tetrahedron needed");
  for (const auto& t : m.tets)
    for (int32_t n : t)
      if (n < 0 || n >= nodes) fail("node id " + std::to_string(n) + " out of range (" + std::to_string(nodes) + " nodes)");
  if (!m.cube_voxels.valid()) fail("cube_voxels must be at least 1 on every axis");
  const std::array<int64_t, 3> need = m.cube_voxels.cubes_for(m.grid.dims);
  for (int a = 0; a < 3; ++a)
    if (m.cubes[a] < need[std::size_t(a)])
      fail("the rest-space table has " + std::to_string(m.cubes[a]) + " cubes on axis " + std::to_string(a) +
           ", fewer than the grid's " + std::to_string(m.grid.dims[a]) + " voxels need");
  if (int64_t(m.cube_meshed.size()) != m.cubes[0] * m.cubes[1] * m.cubes[2]) fail("cube_meshed size");
}

PadVoxels growth_to_hold_deformed(const WarpMesh& m, const Index3& max_voxels) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t n = 0; n < m.rest_ijk.size(); ++n) {
    const Vec3 x = m.rest_ijk[n] + m.disp_ijk[n];
    if (!x.allFinite()) continue;
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  PadVoxels grow;
  if (!(hi.x() >= lo.x())) return grow;   // no finite node
  for (int a = 0; a < 3; ++a) {
    const int64_t L = std::max(1, m.cube_voxels[a]);
    // Voxel cells 0 … n−1 cover [−½, n−½): a rest node on the grid's face needs nothing, a node
    // beyond it the cells out to its place.
    const double below = -lo[a] - 0.5, above = hi[a] + 0.5 - double(m.grid.dims[a]);
    const int64_t cap = std::max<int64_t>(0, max_voxels[a]);
    if (below > 0) grow.lo[a] = std::min((int64_t(std::ceil(below)) + L - 1) / L * L, cap / L * L);
    if (above > 0) grow.hi[a] = std::min(int64_t(std::ceil(above)), cap);
  }
  return grow;
}

WarpMesh grown_warp_mesh(const WarpMesh& m, const PadVoxels& grow) {
  const CubeVoxels& L = m.cube_voxels;
  for (int a = 0; a < 3; ++a)
    if (grow.lo[a] < 0 || grow.hi[a] < 0 || L[a] < 1 || grow.lo[a] % L[a] != 0)
      throw std::invalid_argument("grown_warp_mesh: the low ends must grow by whole cubes of " + L.text() +
                                  " voxels and no end may shrink");
  WarpMesh g = m;
  g.grid = padded_geometry(m.grid, grow);
  const Vec3 shift(double(grow.lo[0]), double(grow.lo[1]), double(grow.lo[2]));
  for (Vec3& x : g.rest_ijk) x += shift;   // displacements are differences: unchanged
  Index3 offset{0, 0, 0};
  for (int a = 0; a < 3; ++a) {
    offset[a] = grow.lo[a] / L[a];
    g.cubes[a] = std::max(m.cubes[a] + offset[a], (g.grid.dims[a] + L[a] - 1) / L[a]);
  }
  g.cube_meshed.assign(std::size_t(g.cubes[0] * g.cubes[1] * g.cubes[2]), 0);
  for (int64_t c = 0; c < m.cubes[2]; ++c)
    for (int64_t b = 0; b < m.cubes[1]; ++b)
      for (int64_t a = 0; a < m.cubes[0]; ++a)
        g.cube_meshed[std::size_t((a + offset[0]) + g.cubes[0] * ((b + offset[1]) + g.cubes[1] * (c + offset[2])))] =
            m.cube_meshed[std::size_t(a + m.cubes[0] * (b + m.cubes[1] * c))];
  return g;
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
