#pragma once
// A small synthetic case for the warp tests: a grid (any spacing and direction), roles laid out as
// a wall shell over a viscera block with a fixed strip behind it (so wall and viscera share doubled
// cubes along a true interface), labels per role, a CT of seeded random HU (the hardest input for
// interpolation: neighbouring voxels differ by up to 2500 HU), and its mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "core/progress.h"
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

/// dims should be multiples of `cube` (per axis) so that every meshed cube lies inside the grid.
inline WarpCase make_warp_case(const Geometry& grid, const CubeVoxels& cube, uint32_t seed) {
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
    const double f = std::floor((p[a] + 0.5) / m.cube_voxels[a]);
    if (!(f >= 0 && f < double(m.cubes[a]))) return 0;
    q[a] = int64_t(f);
  }
  return parts[std::size_t(q[0] + m.cubes[0] * (q[1] + m.cubes[1] * q[2]))];
}

inline Geometry grid_of(Index3 dims, Vec3 spacing, Mat3 direction, Vec3 origin = Vec3(-31.0, 12.5, 140.0)) {
  Geometry g;
  g.dims = dims;
  g.spacing_mm = spacing;
  g.direction = direction;
  g.origin_mm = origin;
  return g;
}

inline Mat3 rotation(double deg, Vec3 axis) {
  return Eigen::AngleAxisd(deg * M_PI / 180.0, axis.normalized()).toRotationMatrix();
}

/// The test's own trilinear interpolation (8 weighted corners), independent of warp_sampling.h.
inline double trilinear(const WarpCase& c, const Vec3& p) {
  const Index3& d = c.grid.dims;
  double sum = 0.0;
  const Eigen::Vector3d fl(std::floor(p[0]), std::floor(p[1]), std::floor(p[2]));
  for (int corner = 0; corner < 8; ++corner) {
    double w = 1.0;
    int64_t q[3];
    for (int a = 0; a < 3; ++a) {
      const int bit = (corner >> a) & 1;
      const double f = p[a] - fl[a];
      w *= bit ? f : 1.0 - f;
      q[a] = std::clamp<int64_t>(int64_t(fl[a]) + bit, 0, d[a] - 1);
    }
    sum += w * c.ct[std::size_t(c.grid.linear_index(q[0], q[1], q[2]))];
  }
  return sum;
}

/// An affine deformation x ↦ M x + b (index coordinates) of a case on an oblique, anisotropic grid.
struct AffineCase {
  WarpCase c;
  Mat3 M;
  Vec3 b;
  WarpMesh mesh;
};
inline AffineCase affine_case() {
  AffineCase a;
  a.c = make_warp_case(grid_of({32, 28, 24}, {0.7, 0.9, 1.3}, rotation(20, Vec3(1, 2, 3))), 4, 13);
  const Vec3 centre(16, 14, 12);
  a.M = rotation(3, Vec3(0.3, -1, 0.5)) * Vec3(1.04, 0.97, 1.02).asDiagonal();
  a.b = centre - a.M * centre + Vec3(1.3, -0.7, 0.4);
  a.mesh = make_warp_mesh(a.c.mesh, displacement_of(a.c, [&](const Vec3& x) { return Vec3(a.M * x + a.b); }));
  return a;
}

/// A warp of affine_case() against analytic affine resampling: the value at P′ is the trilinear
/// interpolation of the input at M⁻¹(P′ − b), the label its nearest voxel's (skipped as a tie where a
/// source coordinate lies within half_band of a half). Only voxels whose source lies in the meshed
/// space, 0.01 voxel clear of its boundary, are checked; each must be carried (else a crack).
struct AffineCheck {
  int64_t checked = 0, cracks = 0, label_ties = 0, label_mismatches = 0;
  double worst_hu = 0.0;
};
inline AffineCheck check_affine(const AffineCase& a, const WarpResult& r, double half_band) {
  const WarpCase& c = a.c;
  const auto parts = cube_parts(c.mesh);
  const Mat3 M_inv = a.M.inverse();
  AffineCheck out;
  for (int64_t k = 0; k < c.grid.dims[2]; ++k)
    for (int64_t j = 0; j < c.grid.dims[1]; ++j)
      for (int64_t i = 0; i < c.grid.dims[0]; ++i) {
        const Vec3 s = M_inv * (Vec3(double(i), double(j), double(k)) - a.b);
        bool clear = true;
        for (int corner = 0; corner < 8 && clear; ++corner) {
          const Vec3 e(corner & 1 ? 0.01 : -0.01, corner & 2 ? 0.01 : -0.01, corner & 4 ? 0.01 : -0.01);
          clear = parts_at(c.mesh, parts, s + e) != 0;
        }
        if (!clear) continue;
        const int64_t n = c.grid.linear_index(i, j, k);
        ++out.checked;
        if (r.outcome[n] != WarpOutcome::Carried) {
          ++out.cracks;
          continue;
        }
        out.worst_hu = std::max(out.worst_hu, std::abs(double(r.ct_hu[n]) - trilinear(c, s)));
        bool tie = false;
        for (int d = 0; d < 3; ++d) tie |= std::abs(s[d] - std::floor(s[d]) - 0.5) < half_band;
        if (tie) {
          ++out.label_ties;
          continue;
        }
        const int64_t v = c.grid.linear_index(int64_t(std::floor(s[0] + 0.5)), int64_t(std::floor(s[1] + 0.5)),
                                              int64_t(std::floor(s[2] + 0.5)));
        if (r.labels[n] != c.labels[v]) ++out.label_mismatches;
      }
  return out;
}

/// Whether rounding may decide the outcome or nearest voxel at index point p: some deformed
/// tetrahedron's weight lies within 1e-5 of −kWarpTolerance there (containment decided by
/// rounding), or a tetrahedron containing p maps it to a source coordinate within 1e-4 of a half
/// (nearest voxel, so role and label, decided by rounding). float32 puts a source point ~1e-5 voxel
/// off; both bands leave room. Loops over every tetrahedron: for the few voxels that differ.
inline bool measured_tie(const WarpMesh& m, const Vec3& p) {
  constexpr double kWeightBand = 1e-5, kHalfBand = 1e-4;
  for (int64_t t = 0; t < m.tet_count(); ++t) {
    if (warp_tet_degenerate(m, t)) continue;
    const auto& v = m.tets[std::size_t(t)];
    const Vec3 x0 = m.deformed_ijk(v[0]), d0 = m.disp_ijk[v[0]];
    Mat3 e, dd;
    e << m.deformed_ijk(v[1]) - x0, m.deformed_ijk(v[2]) - x0, m.deformed_ijk(v[3]) - x0;
    dd << m.disp_ijk[v[1]] - d0, m.disp_ijk[v[2]] - d0, m.disp_ijk[v[3]] - d0;
    const Vec3 w = e.inverse() * (p - x0);
    const double lowest = std::min(1.0 - w.sum(), w.minCoeff());
    if (std::abs(lowest + kWarpTolerance) < kWeightBand) return true;
    if (lowest < -kWarpTolerance - kWeightBand) continue;
    const Vec3 s = p - (d0 + dd * w);
    for (int a = 0; a < 3; ++a)
      if (std::abs(s[a] - std::floor(s[a]) - 0.5) < kHalfBand) return true;
  }
  return false;
}

/// The options the warp tests use: cavity label 250 (no label of the case).
inline WarpOptions warp_test_options() {
  WarpOptions o;
  o.cavity_label = 250;
  return o;
}

/// A 24×24×20 grid with anisotropic spacing and an oblique direction, so index/world slips cannot cancel.
inline Geometry oblique_test_grid() {
  Geometry g;
  g.dims = {24, 24, 20};
  g.spacing_mm = Vec3(0.8, 0.8, 1.6);
  g.direction = Eigen::AngleAxisd(0.3, Vec3(1, 1, 0).normalized()).toRotationMatrix();
  g.origin_mm = Vec3(-20, 35, -110);
  return g;
}

/// A smooth, seeded deformation of the case's mesh with per-node jitter (±0.35 voxel): the wall
/// lifts by about 2.5 voxels and the viscera sink; `toward` > 0 presses them into each other (their
/// tetrahedra then overlap, so "the lowest accepting index wins" decides). `reversed` numbers the
/// tetrahedra last cube first, so owners, not visiting order, must decide.
inline WarpMesh random_warp_mesh(const WarpCase& c, uint32_t seed, double toward, bool reversed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.35, 0.35);
  std::vector<Vec3> u(std::size_t(c.mesh.node_count()));
  for (int64_t n = 0; n < c.mesh.node_count(); ++n) {
    const Vec3 x = c.grid.to_index(1e3 * c.mesh.rest_m[n]);
    const Vec3 smooth = c.mesh.node_part[n] == Part::Wall
                            ? Vec3(0.4 * std::cos(x[2] / 3.0), 2.5 + std::sin(x[0] / 5.0) - 2.5 * toward, 0)
                            : Vec3(0, -0.8 + toward, 0.5 * std::sin(x[1] / 4.0));
    u[std::size_t(n)] = 1e-3 * (c.index_to_mm() * (smooth + Vec3(jitter(rng), jitter(rng), jitter(rng))));
  }
  WarpMesh m = make_warp_mesh(c.mesh, u);
  if (reversed) {
    std::reverse(m.tets.begin(), m.tets.end());
    std::reverse(m.tet_part.begin(), m.tet_part.end());
  }
  return m;
}

/// Two warps of the same mesh and box compared voxel by voxel: where both carry a voxel, the worst
/// CT difference; elsewhere equal outcomes must give equal CT (gas or the voxel's own value, no
/// arithmetic; checked here); every voxel whose outcome or label differs is a measured tie or not.
struct WarpComparison {
  int64_t both_carried = 0, ties = 0, untied = 0;
  double worst_hu = 0.0;
};
inline WarpComparison compare_warps(const WarpResult& a, const WarpResult& b, const WarpMesh& m, const WarpBox& box) {
  WarpComparison out;
  EXPECT_EQ(a.ct_hu.size(), b.ct_hu.size());
  if (a.ct_hu.size() != b.ct_hu.size()) return out;
  for (int64_t k = 0; k < box.dims[2]; ++k)
    for (int64_t j = 0; j < box.dims[1]; ++j)
      for (int64_t i = 0; i < box.dims[0]; ++i) {
        const std::size_t n = std::size_t(i + box.dims[0] * (j + box.dims[1] * k));
        if (a.outcome[n] == WarpOutcome::Carried && b.outcome[n] == WarpOutcome::Carried) {
          ++out.both_carried;
          out.worst_hu = std::max(out.worst_hu, std::abs(double(a.ct_hu[n]) - double(b.ct_hu[n])));
        } else if (a.outcome[n] == b.outcome[n]) {
          EXPECT_EQ(a.ct_hu[n], b.ct_hu[n]);
        }
        if (a.outcome[n] == b.outcome[n] && a.labels[n] == b.labels[n]) continue;
        ++(measured_tie(m, Vec3(double(i + box.lo[0]), double(j + box.lo[1]), double(k + box.lo[2]))) ? out.ties
                                                                                                      : out.untied);
      }
  return out;
}

/// The warp tests' fixture: no progress lines.
class QuietWarpTest : public ::testing::Test {
 protected:
  void SetUp() override { Progress::set_enabled(false); }
};

/// Two warps equal bit for bit: CT (as bytes, so -0 and NaN patterns count), labels and outcomes.
inline void expect_same_bits(const WarpResult& a, const WarpResult& b) {
  ASSERT_EQ(a.ct_hu.size(), b.ct_hu.size());
  EXPECT_EQ(std::memcmp(a.ct_hu.data(), b.ct_hu.data(), a.ct_hu.size() * sizeof(float)), 0);
  EXPECT_EQ(a.labels, b.labels);
  EXPECT_EQ(a.outcome, b.outcome);
}

/// The affine closed form held to: more than 3000 voxels checked, no crack, CT within `hu_tolerance`
/// of the analytic resampling, labels exact outside `half_band` of a half-voxel tie. Returns the check.
inline AffineCheck expect_affine_truth(const AffineCase& a, const WarpResult& r, double half_band, double hu_tolerance) {
  const AffineCheck check = check_affine(a, r, half_band);
  EXPECT_GT(check.checked, 3000);
  EXPECT_EQ(check.cracks, 0) << "voxels inside the deformed mesh left uncovered";
  EXPECT_LE(check.worst_hu, hu_tolerance) << "HU off analytic affine resampling";
  EXPECT_EQ(check.label_mismatches, 0) << "labels off the nearest source voxel";
  return check;
}

}  // namespace pneumo::testing_support
