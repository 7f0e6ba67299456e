// The output grid grown to hold a deformed body that left the working grid (warp_mesh.h
// growth_to_hold_deformed and grown_warp_mesh, roles.h grown_roles). Truths: a body translated out
// of the grid by whole voxels is carried whole into the grown
// grid (every voxel it carried at rest, none clipped); on the original grid's voxels the grown warp
// is the original warp bit for bit (the rest-space table and index shift agree) but for tissue
// sampled in the last half voxel of a face that grew, which the original clamps to the edge voxel
// and the grown grid blends with its air, as on a padded side; nothing grows while the body stays
// inside; the low ends grow by whole cubes; a cap holds.
#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>

#include "roles/roles.h"
#include "warp/point_map.h"
#include "warp/warp.h"
#include "warp_test_support.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

class WarpGrow : public QuietWarpTest {};

constexpr Index3 kNoCap{1000, 1000, 1000};

/// The case's arrays as the roles' working grid, grown by `grow`.
RoleVolume grown_case(const WarpCase& c, const PadVoxels& grow) {
  RoleVolume rv;
  rv.geometry = c.grid;
  rv.role = c.roles;
  rv.label = c.labels;
  rv.ct = Volume(c.grid, VoxelType::Float32);
  std::memcpy(rv.ct.raw(), c.ct.data(), c.ct.size() * sizeof(float));
  return grown_roles(std::move(rv), grow);
}

WarpResult warp_grown(const WarpMesh& m, const RoleVolume& rv) {
  const WarpSource src{rv.ct.data<float>(), rv.label.data(), rv.role.data()};
  return warp_cpu(m, src, WarpBox{{0, 0, 0}, rv.geometry.dims}, warp_test_options());
}

}  // namespace

// Cubes of 2 voxels: the meshes end 2 voxels short of the i and k faces (the case's fractions of
// 24 and 16), so a shift of one voxel along them keeps every node inside; with cubes of 4 the
// meshed cubes reach the faces, where rest nodes sit on them and still ask for nothing.
TEST_F(WarpGrow, NothingGrowsWhileTheBodyStaysInside) {
  const WarpCase c = make_warp_case(grid_of({24, 24, 16}, {1.0, 1.0, 1.0}, Mat3::Identity()), 2, 21);
  const WarpCase on_faces = make_warp_case(c.grid, 4, 21);
  EXPECT_TRUE(
      growth_to_hold_deformed(make_warp_mesh(on_faces.mesh, uniform_displacement(on_faces, Vec3::Zero())), kNoCap)
          .empty());
  EXPECT_TRUE(growth_to_hold_deformed(make_warp_mesh(c.mesh, uniform_displacement(c, Vec3(1, 0, -1))), kNoCap).empty());
}

// Cubes of 4 voxels: the meshed cubes of a 24×24×16 grid reach its i and k faces (nodes at −½ and
// n − ½). Shifted by (−5, 0, +6) voxels, they leave by 5 voxels at the low i end (two whole cubes
// of growth) and 6 at the high k end. Whole-voxel shifts keep every sample
// exact, so the grown grid must carry exactly as many voxels as the rest configuration holds, while
// the original grid clips some. The direction is a quarter turn and the spacing anisotropic, so an
// index/world slip cannot cancel.
TEST_F(WarpGrow, ABodyMovedOutOfTheGridIsCarriedWhole) {
  Mat3 quarter_turn;
  quarter_turn << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const WarpCase c = make_warp_case(grid_of({24, 24, 16}, {0.5, 1.0, 2.0}, quarter_turn), 4, 22);
  const Vec3 shift(-5, 0, 6);
  const WarpMesh m = make_warp_mesh(c.mesh, uniform_displacement(c, shift));
  const PadVoxels grow = growth_to_hold_deformed(m, kNoCap);
  EXPECT_EQ(grow.lo, (Index3{8, 0, 0}));
  EXPECT_EQ(grow.hi, (Index3{0, 0, 6}));

  const WarpMesh g = grown_warp_mesh(m, grow);
  const RoleVolume rv = grown_case(c, grow);
  ASSERT_EQ(rv.geometry.dims, g.grid.dims);
  EXPECT_EQ(rv.pad.lo, grow.lo);
  EXPECT_TRUE((rv.geometry.origin_mm - c.grid.to_world(Vec3(-8, 0, 0))).norm() < 1e-12);
  // Every deformed node lies in a cell of the grown grid.
  for (std::size_t n = 0; n < g.rest_ijk.size(); ++n)
    for (int a = 0; a < 3; ++a) {
      const double x = g.rest_ijk[n][a] + g.disp_ijk[n][a];
      EXPECT_GE(x, -0.5);
      EXPECT_LE(x, double(g.grid.dims[a]) - 0.5);
    }

  const WarpResult rest = warp_cpu(make_warp_mesh(c.mesh, uniform_displacement(c, Vec3::Zero())), c.source(),
                                   c.whole(), warp_test_options());
  const WarpResult clipped = warp_cpu(m, c.source(), c.whole(), warp_test_options());
  const WarpResult grown = warp_grown(g, rv);
  EXPECT_EQ(grown.carried_voxels, rest.carried_voxels);
  EXPECT_LT(clipped.carried_voxels, rest.carried_voxels);
  // The wall's labels all arrive: as many wall-labelled voxels after as before.
  const auto count = [](const std::vector<uint16_t>& l, uint16_t id) { return std::count(l.begin(), l.end(), id); };
  EXPECT_EQ(count(grown.labels, kWallLabel), count(c.labels, kWallLabel));
  EXPECT_LT(count(clipped.labels, kWallLabel), count(c.labels, kWallLabel));
}

// Where the two grids overlap, the grown warp is the original warp: same HU bits, labels and
// outcomes (a smooth non-uniform deformation, so tetrahedra are cut by every rule), except where a
// voxel's source lies in the last half voxel beyond the edge voxels' centres on a side that grew
// (clamped there, blended with air here; warp_sampling.h). Each difference is traced to such a source.
TEST_F(WarpGrow, OnTheOriginalVoxelsTheGrownWarpIsTheOriginal) {
  const WarpCase c = make_warp_case(grid_of({24, 24, 16}, {0.75, 0.75, 1.5}, rotation(25, Vec3(1, 2, 3))), 4, 23);
  const WarpMesh m = make_warp_mesh(c.mesh, displacement_of(c, [](const Vec3& x) {
    return Vec3(x + Vec3(-2.6 + 0.3 * std::sin(x[2]), 0.7, 0.2 * x[0] - 1.1));
  }));
  const PadVoxels grow = growth_to_hold_deformed(m, kNoCap);
  ASSERT_FALSE(grow.empty());
  const WarpResult original = warp_cpu(m, c.source(), c.whole(), warp_test_options());
  const WarpResult grown = warp_grown(grown_warp_mesh(m, grow), grown_case(c, grow));
  const Index3 gd = padded_geometry(c.grid, grow).dims;
  const PointMap map(m, c.roles.data());
  int64_t same = 0, at_a_grown_face = 0, unexplained = 0;
  for (int64_t k = 0; k < c.grid.dims[2]; ++k)
    for (int64_t j = 0; j < c.grid.dims[1]; ++j)
      for (int64_t i = 0; i < c.grid.dims[0]; ++i) {
        const int64_t o = c.grid.linear_index(i, j, k);
        const int64_t w = (i + grow.lo[0]) + gd[0] * ((j + grow.lo[1]) + gd[1] * (k + grow.lo[2]));
        if (std::memcmp(&grown.ct_hu[w], &original.ct_hu[o], sizeof(float)) == 0 &&
            grown.labels[w] == original.labels[o] && grown.outcome[w] == original.outcome[o]) {
          ++same;
          continue;
        }
        const MappedPoint src = map.to_original(c.grid.to_world(Vec3(double(i), double(j), double(k))));
        const Vec3 p = c.grid.to_index(src.point_mm);
        bool clamped = false;
        for (int a = 0; a < 3; ++a)
          clamped |= (grow.lo[a] > 0 && p[a] < 0.0) || (grow.hi[a] > 0 && p[a] > double(c.grid.dims[a] - 1));
        (src.carried && clamped ? at_a_grown_face : unexplained) += 1;
      }
  EXPECT_EQ(unexplained, 0);
  EXPECT_GT(same, 20 * at_a_grown_face);
  EXPECT_GE(grown.carried_voxels, original.carried_voxels);
}

TEST_F(WarpGrow, TheCapHoldsAndTheLowEndsStayOnTheLattice) {
  const WarpCase c = make_warp_case(grid_of({24, 24, 16}, {1.0, 1.0, 1.0}, Mat3::Identity()), 4, 24);
  const WarpMesh m = make_warp_mesh(c.mesh, uniform_displacement(c, Vec3(-30, 0, 40)));
  const PadVoxels capped = growth_to_hold_deformed(m, Index3{10, 10, 10});
  EXPECT_EQ(capped.lo[0], 8);   // the cap of 10, rounded down to whole cubes
  EXPECT_EQ(capped.hi[2], 10);
  PadVoxels off_lattice;
  off_lattice.lo = {3, 0, 0};
  EXPECT_THROW(grown_warp_mesh(m, off_lattice), std::invalid_argument);
  PadVoxels shrinking;
  shrinking.hi = {0, -1, 0};
  EXPECT_THROW(grown_warp_mesh(m, shrinking), std::invalid_argument);
}
