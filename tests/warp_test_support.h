#pragma once
// A small synthetic case for the warp tests: a grid (any spacing and direction), roles laid out as
// a wall shell over a viscera block with a fixed strip behind it (so wall and viscera share doubled
// cubes along a true interface), labels per role, a CT of seeded random HU (the hardest input for
// interpolation: neighbouring voxels differ by up to 2500 HU), and its mesh.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "core/units.h"
#include "mesh/mesh.h"
#include "warp/warp.h"
#include "warp/warp_sampling.h"

namespace pneumo::testing_support {

struct WarpCase {
  Geometry grid;
  std::vector<Role> roles;
  std::vector<uint16_t> labels;
  std::vector<float> ct;
  Mesh mesh;

  WarpSource source() const { return WarpSource{ct.data(), labels.data(), roles.data()}; }
  WarpBox whole() const { return WarpBox{{0, 0, 0}, grid.dims}; }
  SourceGrid sampler() const { return SourceGrid{grid.dims, ct.data(), labels.data(), roles.data()}; }
  /// Linear part of index → world (mm): direction · diag(spacing).
  Mat3 index_to_mm() const { return grid.direction * grid.spacing_mm.asDiagonal(); }
};

// Label ids by role (the cavity label of the tests, 250, is none of them).
constexpr uint16_t kWallLabel = 10, kOrganA = 20, kOrganB = 21, kFixedLabel = 30;

/// dims should be multiples of `cube` so that every meshed cube lies inside the grid.
inline WarpCase make_warp_case(const Geometry& grid, int cube, uint32_t seed) {
  WarpCase c;
  c.grid = grid;
  const Index3 d = grid.dims;
  const int64_t n = grid.voxel_count();
  c.roles.assign(std::size_t(n), Role::Other);
  c.labels.assign(std::size_t(n), 0);
  c.ct.resize(std::size_t(n));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> hu(-1000.0f, 1500.0f);
  for (auto& v : c.ct) v = hu(rng);
  // In fractions of the grid along j ("anterior"): fixed strip, viscera block, wall shell on top.
  const int64_t j_fixed = d[1] / 12, j_visc = d[1] / 6, j_wall = d[1] / 2 + 1, j_top = (2 * d[1]) / 3 + 1;
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i) {
        const int64_t v = grid.linear_index(i, j, k);
        const bool core_i = i >= d[0] / 6 && i < d[0] - d[0] / 6, core_k = k >= d[2] / 4 && k < d[2] - d[2] / 4;
        const bool wide_i = i >= d[0] / 12 && i < d[0] - d[0] / 12, wide_k = k >= d[2] / 8 && k < d[2] - d[2] / 8;
        if (core_i && core_k && j >= j_fixed && j < j_visc) {
          c.roles[v] = Role::Fixed;
          c.labels[v] = kFixedLabel;
        } else if (core_i && core_k && j >= j_visc && j < j_wall) {
          c.roles[v] = Role::Viscera;
          c.labels[v] = i < d[0] / 2 ? kOrganA : kOrganB;
        } else if (wide_i && wide_k && j >= j_wall && j < j_top) {
          c.roles[v] = Role::Wall;
          c.labels[v] = kWallLabel;
        }
      }
  MeshOptions opt;
  opt.cube_voxels = cube;
  c.mesh = build_mesh(VoxelRoles{grid, c.roles.data(), c.labels.data()}, opt, [](Role, int) { return 1000.0; });
  return c;
}

/// Node displacements (metres) of a map given in index coordinates: u = f(x) − x.
template <class F>
std::vector<Vec3> displacement_of(const WarpCase& c, F&& f_ijk) {
  std::vector<Vec3> u(std::size_t(c.mesh.node_count()));
  const Mat3 a = c.index_to_mm();
  for (int64_t n = 0; n < c.mesh.node_count(); ++n) {
    const Vec3 x = c.grid.to_index(units::m_to_mm(1.0) * c.mesh.rest_m[n]);
    u[std::size_t(n)] = units::mm_to_m(1.0) * (a * (f_ijk(x) - x));
  }
  return u;
}

/// The same displacement, given in index units, for every node (exact: no per-node rounding).
inline std::vector<Vec3> uniform_displacement(const WarpCase& c, const Vec3& shift_ijk) {
  return std::vector<Vec3>(std::size_t(c.mesh.node_count()), units::mm_to_m(1.0) * (c.index_to_mm() * shift_ijk));
}

/// Which parts mesh each lattice cube: bit 0 wall, bit 1 viscera.
inline std::vector<uint8_t> cube_parts(const Mesh& m) {
  std::vector<uint8_t> parts(std::size_t(m.cubes[0] * m.cubes[1] * m.cubes[2]), 0);
  for (std::size_t t = 0; t < m.tets.size(); ++t)
    parts[std::size_t(m.tet_cube[t])] |= m.tet_part[t] == Part::Wall ? 1 : 2;
  return parts;
}

/// The parts (cube_parts bits) meshing the cube that holds index point p (continuous); 0 outside.
inline uint8_t parts_at(const Mesh& m, const std::vector<uint8_t>& parts, const Vec3& p) {
  int64_t q[3];
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor((p[a] + 0.5) / m.cube_voxels);
    if (!(f >= 0 && f < double(m.cubes[a]))) return 0;
    q[a] = int64_t(f);
  }
  return parts[std::size_t(q[0] + m.cubes[0] * (q[1] + m.cubes[1] * q[2]))];
}

}  // namespace pneumo::testing_support
