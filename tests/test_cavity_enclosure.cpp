// Rule 5 of the warp (host/warp/cavity_enclosure.h): the space between the skin's rest place and the
// inner face of a wall that rose by more than its thickness is gas, whatever the cube size.
//  - A slab of wall over a block of viscera, the wall lifted by a sine bump of 6.7 voxels over a
//    3-voxel wall: the gas in each column is exactly the voxel centres between the viscera's face and
//    the lifted inner face (the lift at a column is the tetrahedra's linear interpolation of the
//    nodes' lifts, exact for this map), at 1- and 2-voxel cubes alike. The back end alone (rules 1–4)
//    misses the part above the rest skin, which is what the rule adds.
//  - By hand: air enclosed at rest (an `other` role inside the body) stays what it was; air that
//    reaches the slice's border stays; a slice's enclosure does not leak into the next slice.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/units.h"
#include "mesh/mesh.h"
#include "warp/cavity_enclosure.h"
#include "warp/warp.h"
#include "warp_test_support.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

constexpr double kLiftVoxels = 6.7;   // peak lift; the wall is 3 voxels thick
constexpr int64_t kNi = 24, kNj = 22, kNk = 4;
constexpr int64_t kViscTop = 8, kWallTop = 11;   // viscera j < 8, wall 8 ≤ j < 11 (i in [2, 22))

/// The lift of the wall (index units along +j) at index x: zero at the wall's ends (x = 1.5, 21.5).
double lift_at(double x) { return kLiftVoxels * std::sin(M_PI * (x - 1.5) / 20.0); }

/// warp_test_support.h's case, laid out by hand: a slab of wall over a block of viscera.
WarpCase make_slab(int cube) {
  WarpCase s;
  s.grid = grid_of({kNi, kNj, kNk}, {1.0, 1.0, 1.0}, Mat3::Identity());
  const int64_t n = s.grid.voxel_count();
  s.roles.assign(std::size_t(n), Role::Other);
  s.labels.assign(std::size_t(n), 0);
  s.ct.assign(std::size_t(n), -1000.0f);
  for (int64_t k = 0; k < kNk; ++k)
    for (int64_t j = 2; j < kWallTop; ++j)
      for (int64_t i = 2; i < kNi - 2; ++i) {
        const int64_t v = s.grid.linear_index(i, j, k);
        const bool wall = j >= kViscTop;
        s.roles[v] = wall ? Role::Wall : Role::Viscera;
        s.labels[v] = wall ? kWallLabel : kOrganA;
        s.ct[v] = wall ? 40.0f : 30.0f;
      }
  MeshOptions opt;
  opt.cube_voxels = cube;
  s.mesh = build_mesh(VoxelRoles{s.grid, s.roles.data(), s.labels.data()}, opt, [](Role, int) { return 1000.0; });
  return s;
}

/// The wall's nodes lifted along +j by lift_at(their i), the viscera's left in place.
WarpMesh lifted(const WarpCase& s) {
  std::vector<Vec3> u(std::size_t(s.mesh.node_count()), Vec3::Zero());
  for (int64_t n = 0; n < s.mesh.node_count(); ++n) {
    if (s.mesh.node_part[std::size_t(n)] != Part::Wall) continue;
    const Vec3 x = s.grid.to_index(units::m_to_mm(1.0) * s.mesh.rest_m[std::size_t(n)]);
    u[std::size_t(n)] = units::mm_to_m(1.0) * Vec3(0.0, lift_at(x[0]), 0.0);   // spacing 1 mm, identity
  }
  return make_warp_mesh(s.mesh, u);
}

/// The gas voxels each column (i) should hold in one slice: centres j with
/// kViscTop − ½ < j < kViscTop − ½ + ū(i), ū the linear interpolation between the nodes (spaced
/// `cube` voxels, at i = cube·c − ½) bracketing the column's centre.
std::vector<int64_t> expected_gas_per_column(int cube) {
  std::vector<int64_t> out(std::size_t(kNi), 0);
  for (int64_t i = 2; i < kNi - 2; ++i) {
    const double lo = std::floor((double(i) + 0.5) / cube) * cube - 0.5, hi = lo + cube;
    const double t = (double(i) - lo) / cube;
    const double lift = (1.0 - t) * lift_at(lo) + t * lift_at(hi);
    const double face = double(kViscTop) - 0.5 + lift;
    EXPECT_GT(std::abs(face - std::round(face)), 1e-3) << "a voxel centre on the face: pick another lift";
    for (int64_t j = kViscTop; double(j) < face; ++j) ++out[std::size_t(i)];
  }
  return out;
}

WarpOptions options() { return warp_test_options(); }

class CavityEnclosure : public QuietWarpTest {};

}  // namespace

TEST_F(CavityEnclosure, GasFillsTheSpaceUnderAWallLiftedBeyondItsThicknessAtEveryCubeSize) {
  for (int cube : {1, 2}) {
    SCOPED_TRACE("cube " + std::to_string(cube));
    const WarpCase s = make_slab(cube);
    const WarpMesh m = lifted(s);
    const WarpBox box{{0, 0, 0}, s.grid.dims};
    const WarpResult back_end = warp_cpu(m, s.source(), box, options());
    const WarpResult r = warp_on_device("cpu", m, s.source(), box, options());
    const std::vector<int64_t> expected = expected_gas_per_column(cube);
    int64_t expected_total = 0, wrong_columns = 0;
    for (int64_t k = 0; k < kNk; ++k)
      for (int64_t i = 0; i < kNi; ++i) {
        int64_t gas = 0;
        for (int64_t j = 0; j < kNj; ++j) {
          const std::size_t v = std::size_t(s.grid.linear_index(i, j, k));
          if (r.outcome[v] != WarpOutcome::Gas) continue;
          ++gas;
          EXPECT_EQ(r.labels[v], options().cavity_label);
          EXPECT_EQ(r.ct_hu[v], options().gas_hu);
        }
        wrong_columns += gas != expected[std::size_t(i)];
        expected_total += expected[std::size_t(i)];
      }
    EXPECT_EQ(wrong_columns, 0);
    EXPECT_EQ(r.gas_voxels, expected_total);
    EXPECT_EQ(r.gas_voxels + r.carried_voxels + r.kept_voxels, s.grid.voxel_count());
    // Without rule 5 the space above the rest skin (j ≥ 11 where the lift exceeds 3.5 voxels) is missed.
    EXPECT_LT(back_end.gas_voxels, expected_total - 4 * kNk);
  }
}

// A 7×7×2 box by hand: after the warp a ring of carried voxels (i or j = 1 or 5) around a kept
// inside (i, j in 2–4), the ring open at (5, 3) in slice 1. First the inside was the body at rest
// (wall, around an `other` voxel the body enclosed): nothing becomes gas. Then only (2, 2) was the
// body at rest: the rest of the inside was outside air then and becomes gas in slice 0; in slice 1
// the opening joins it to the border, and it stays.
TEST_F(CavityEnclosure, OnlyAirOutsideTheBodyAtRestAndEnclosedNowBecomesGas) {
  const Geometry grid = grid_of({7, 7, 2}, {1.0, 1.0, 1.0}, Mat3::Identity());
  const int64_t n = grid.voxel_count();
  std::vector<Role> roles(std::size_t(n), Role::Other);
  // At rest the body is the ring i, j in [2, 4] except the centre: (3, 3) is enclosed `other`.
  for (int64_t k = 0; k < 2; ++k)
    for (int64_t j = 2; j <= 4; ++j)
      for (int64_t i = 2; i <= 4; ++i)
        if (!(i == 3 && j == 3)) roles[std::size_t(grid.linear_index(i, j, k))] = Role::Wall;
  std::vector<float> ct(std::size_t(n), 7.0f);
  std::vector<uint16_t> labels(std::size_t(n), 3);
  WarpResult r;
  r.outcome.assign(std::size_t(n), WarpOutcome::Kept);
  r.ct_hu = ct;
  r.labels = labels;
  for (int64_t k = 0; k < 2; ++k)
    for (int64_t j = 1; j <= 5; ++j)
      for (int64_t i = 1; i <= 5; ++i) {
        const bool ring = j == 1 || j == 5 || i == 1 || i == 5;
        if (ring && !(k == 1 && i == 5 && j == 3)) r.outcome[std::size_t(grid.linear_index(i, j, k))] = WarpOutcome::Carried;
      }
  // The ring's inside at rest was the body: pretend the warp carried nothing there (all kept),
  // so only the rest roles decide.
  r.carried_voxels = 0;
  for (auto o : r.outcome) r.carried_voxels += o == WarpOutcome::Carried;
  r.kept_voxels = n - r.carried_voxels;
  WarpMesh mesh;   // no cube meshed at rest: only the roles say what was the body
  mesh.grid = grid;
  mesh.cube_voxels = 1;
  mesh.cubes = {7, 7, 2};
  mesh.cube_meshed.assign(std::size_t(n), 0);
  const WarpSource src{ct.data(), labels.data(), roles.data()};
  const int64_t enclosed = enclose_cavity(r, mesh, src, WarpBox{{0, 0, 0}, grid.dims}, options());
  auto at = [&](int64_t i, int64_t j, int64_t k) { return std::size_t(grid.linear_index(i, j, k)); };
  // Every voxel inside the ring was the body at rest (wall) or air the body enclosed then: none is gas.
  EXPECT_EQ(enclosed, 0);
  EXPECT_EQ(r.outcome[at(3, 3, 0)], WarpOutcome::Kept);

  // Now the body at rest was only (2, 2): the rest of the ring's inside was outside air then.
  std::fill(roles.begin(), roles.end(), Role::Other);
  roles[at(2, 2, 0)] = roles[at(2, 2, 1)] = Role::Wall;
  const int64_t enclosed2 = enclose_cavity(r, mesh, src, WarpBox{{0, 0, 0}, grid.dims}, options());
  // Slice 0: the 3×3 inside minus (2, 2) (body at rest) = 8 voxels become gas. Slice 1: the gap at
  // (5, 3) opens the inside to the border, so none.
  EXPECT_EQ(enclosed2, 8);
  for (int64_t j = 2; j <= 4; ++j)
    for (int64_t i = 2; i <= 4; ++i) {
      const bool gas = !(i == 2 && j == 2);
      EXPECT_EQ(r.outcome[at(i, j, 0)], gas ? WarpOutcome::Gas : WarpOutcome::Kept) << i << "," << j;
      EXPECT_EQ(r.labels[at(i, j, 0)], gas ? options().cavity_label : uint16_t(3));
      EXPECT_EQ(r.ct_hu[at(i, j, 0)], gas ? options().gas_hu : 7.0f);
      EXPECT_EQ(r.outcome[at(i, j, 1)], WarpOutcome::Kept) << i << "," << j;
    }
  EXPECT_EQ(r.outcome[at(0, 0, 0)], WarpOutcome::Kept);
  EXPECT_EQ(r.gas_voxels, 8);
  EXPECT_EQ(r.gas_voxels + r.carried_voxels + r.kept_voxels, n);
}
