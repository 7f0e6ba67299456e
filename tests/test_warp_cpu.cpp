// The fast CPU warp (host/warp/warp_cpu.cpp) against closed forms (method.md §10):
// identity, whole-voxel translation, affine resampling, no cracks, role acceptance and the gas rule
// (§7), thread independence; and the point mapping against the same truths and the image warp.
// Every case runs on a small synthetic grid (warp_test_support.h) with random HU, on grids with
// anisotropic spacing and non-identity directions, so index/world slips cannot cancel.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <set>

#include "core/progress.h"
#include "warp/point_map.h"
#include "warp/warp.h"
#include "warp_test_support.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

WarpOptions options() { return warp_test_options(); }

class WarpCpu : public QuietWarpTest {};

}  // namespace

// Identity: zero displacement must return the input bit for bit (CT and labels), carry every
// voxel of the meshed cubes and make no gas. Tolerance: none (the source point is the voxel centre
// exactly, and trilinear weights 1 and 0 reproduce it).
TEST_F(WarpCpu, IdentityReturnsTheInputBitForBit) {
  const WarpCase c = make_warp_case(grid_of({24, 24, 16}, {0.75, 0.75, 1.5}, Vec3(-1, -1, 1).asDiagonal()), 4, 11);
  const WarpMesh m = make_warp_mesh(c.mesh, std::vector<Vec3>(std::size_t(c.mesh.node_count()), Vec3::Zero()));
  const WarpResult r = warp_cpu(m, c.source(), c.whole(), options());
  ASSERT_EQ(r.ct_hu.size(), c.ct.size());
  EXPECT_EQ(std::memcmp(r.ct_hu.data(), c.ct.data(), c.ct.size() * sizeof(float)), 0);
  EXPECT_EQ(r.labels, c.labels);
  EXPECT_EQ(r.gas_voxels, 0);
  int64_t meshed = 0;
  for (int64_t k = 0; k < 16; ++k)
    for (int64_t j = 0; j < 24; ++j)
      for (int64_t i = 0; i < 24; ++i) meshed += m.in_rest_space(i, j, k);
  EXPECT_GT(meshed, 0);
  EXPECT_EQ(r.carried_voxels, meshed);
  EXPECT_EQ(r.kept_voxels, c.grid.voxel_count() - meshed);
}

// A translation by whole voxels of both meshes shifts the image exactly: a voxel whose source
// (itself minus the shift) lies in a meshed cube gets that voxel's value and label bit for bit; the
// meshed space it vacated is gas; everything else keeps its value. Tolerance: none. Spacing in
// powers of two and a 90° rotated direction keep the displacement exactly whole in index units.
TEST_F(WarpCpu, WholeVoxelTranslationShiftsExactly) {
  Mat3 quarter_turn;   // 90° about z, written exactly (AngleAxis leaves 6e-17 for cos 90°)
  quarter_turn << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const WarpCase c = make_warp_case(grid_of({24, 24, 16}, {0.5, 1.0, 2.0}, quarter_turn), 4, 12);
  const Vec3 shift(2, -1, 1);
  const WarpMesh m = make_warp_mesh(c.mesh, uniform_displacement(c, shift));
  const WarpResult r = warp_cpu(m, c.source(), c.whole(), options());
  const auto parts = cube_parts(c.mesh);
  int64_t carried = 0, gas = 0, bad = 0;
  for (int64_t k = 0; k < 16; ++k)
    for (int64_t j = 0; j < 24; ++j)
      for (int64_t i = 0; i < 24; ++i) {
        const int64_t n = c.grid.linear_index(i, j, k);
        const Vec3 s = Vec3(double(i), double(j), double(k)) - shift;
        if (parts_at(c.mesh, parts, s)) {
          const int64_t v = c.grid.linear_index(int64_t(s[0]), int64_t(s[1]), int64_t(s[2]));
          ++carried;
          bad += r.outcome[n] != WarpOutcome::Carried || r.ct_hu[n] != c.ct[v] || r.labels[n] != c.labels[v];
        } else if (m.in_rest_space(i, j, k)) {
          ++gas;
          bad += r.outcome[n] != WarpOutcome::Gas || r.ct_hu[n] != -1000.0f || r.labels[n] != 250;
        } else {
          bad += r.outcome[n] != WarpOutcome::Kept || r.ct_hu[n] != c.ct[n] || r.labels[n] != c.labels[n];
        }
      }
  EXPECT_EQ(bad, 0) << "voxels off the exact shift";
  EXPECT_GT(gas, 0);
  EXPECT_EQ(r.carried_voxels, carried);
  EXPECT_EQ(r.gas_voxels, gas);
}

// An affine deformation x' = M x + b (index coordinates; affine in world too) against analytic
// affine resampling: the value at P' is the trilinear interpolation of the input at M⁻¹(P' − b),
// computed here by the test's own interpolation. Tolerance 1e-3 HU: the reference works in double
// and rounds once to float (ulp 1.2e-4 at 1500 HU). No cracks: every voxel whose source lies in
// the meshed space (0.01 voxel clear of its boundary) must be carried, none may be gas.
TEST_F(WarpCpu, AffineMatchesAnalyticResamplingWithNoCracks) {
  const AffineCase a = affine_case();
  const WarpResult r = warp_cpu(a.mesh, a.c.source(), a.c.whole(), options());
  const AffineCheck check = expect_affine_truth(a, r, 1e-6, 1e-3);
  std::printf("affine: %lld voxels checked, max |Δ| %.2e HU, %lld nearest-label ties skipped\n",
              (long long)check.checked, check.worst_hu, (long long)check.label_ties);
}

// Role acceptance and the gas rule (§7): the wall rises 3 voxels, the viscera sink 1. In the doubled
// cubes along the interface the wall's tetrahedra must take only wall (non-viscera) sources and the
// viscera's only non-wall ones, so the 4-voxel gap that opens is gas (−1000 HU, the cavity label),
// covered by deformed tetrahedra that accept nothing there or vacated by both. Everything is exact:
// each voxel's expected value follows from the rule by hand (no two accepting tetrahedra overlap).
TEST_F(WarpCpu, WallAndVisceraSeparateAlongTheInterfaceAndTheGapIsGas) {
  const WarpCase c = make_warp_case(grid_of({24, 24, 16}, {1.0, 1.0, 1.0}, Mat3::Identity()), 4, 14);
  const Vec3 up(0, 3, 0), down(0, -1, 0);
  std::vector<Vec3> u(std::size_t(c.mesh.node_count()));
  for (int64_t n = 0; n < c.mesh.node_count(); ++n)
    u[std::size_t(n)] = units::mm_to_m(1.0) * (c.mesh.node_part[n] == Part::Wall ? up : down);
  const WarpMesh m = make_warp_mesh(c.mesh, u);
  const WarpResult r = warp_cpu(m, c.source(), c.whole(), options());
  const auto parts = cube_parts(c.mesh);
  const SourceGrid g = c.sampler();
  int64_t bad = 0, gas = 0, wall_carried = 0, viscera_carried = 0;
  for (int64_t k = 0; k < 16; ++k)
    for (int64_t j = 0; j < 24; ++j)
      for (int64_t i = 0; i < 24; ++i) {
        const Vec3 p = Vec3(double(i), double(j), double(k));
        const Vec3 sw = p - up, sv = p - down;
        const bool cover_w = parts_at(c.mesh, parts, sw) & 1, cover_v = parts_at(c.mesh, parts, sv) & 2;
        const bool take_w = cover_w && g.role_nearest(sw) != Role::Viscera;
        const bool take_v = cover_v && g.role_nearest(sv) != Role::Wall;
        ASSERT_FALSE(take_w && take_v) << "the case was meant to have no overlap";
        const int64_t n = c.grid.linear_index(i, j, k);
        if (take_w || take_v) {
          const Vec3 s = take_w ? sw : sv;
          const int64_t v = c.grid.linear_index(int64_t(s[0]), int64_t(s[1]), int64_t(s[2]));
          ++(take_w ? wall_carried : viscera_carried);
          bad += r.outcome[n] != WarpOutcome::Carried || r.ct_hu[n] != c.ct[v] || r.labels[n] != c.labels[v];
          if (take_w) {
            EXPECT_NE(c.roles[v], Role::Viscera);
          }
        } else if (cover_w || cover_v || m.in_rest_space(i, j, k)) {
          ++gas;
          bad += r.outcome[n] != WarpOutcome::Gas || r.ct_hu[n] != -1000.0f || r.labels[n] != 250;
        } else {
          bad += r.outcome[n] != WarpOutcome::Kept || r.ct_hu[n] != c.ct[n];
        }
      }
  EXPECT_EQ(bad, 0);
  EXPECT_GT(wall_carried, 0);
  EXPECT_GT(viscera_carried, 0);
  // The gap between the wall's underside and the viscera's top: 3 + 1 voxels across the interface.
  int64_t gap_column = 0;
  for (int64_t j = 0; j < 24; ++j)
    gap_column += r.outcome[std::size_t(c.grid.linear_index(12, j, 8))] == WarpOutcome::Gas;
  EXPECT_EQ(gap_column, 4);
  EXPECT_EQ(r.gas_voxels, gas);
}

// The result does not depend on the thread count (a tile's voxels belong to one thread at a time,
// and the lowest accepting index wins by comparison, not by visiting order). A smooth random deformation with per-node jitter; compared bit for bit.
TEST_F(WarpCpu, SameBitsOnOneAndTwoThreads) {
  const WarpCase c = make_warp_case(grid_of({24, 20, 16}, {0.8, 0.8, 1.6}, rotation(-15, Vec3(0, 1, 1))), 4, 15);
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  auto u = displacement_of(c, [&](const Vec3& x) {
    return Vec3(x + Vec3(1.5 * std::sin(x[1] / 5.0), 1.0 * std::cos(x[0] / 4.0), jitter(rng)));
  });
  const WarpMesh m = make_warp_mesh(c.mesh, u);
  const int before = omp_get_max_threads();
  omp_set_num_threads(1);
  const WarpResult one = warp_cpu(m, c.source(), c.whole(), options());
  omp_set_num_threads(2);
  const WarpResult two = warp_cpu(m, c.source(), c.whole(), options());
  omp_set_num_threads(before);
  expect_same_bits(one, two);
  EXPECT_GT(one.carried_voxels, 0);
}

// A series of warps reuses its memory (WarpSeries): each warp must give the bits a fresh one gives,
// whatever the last warp left there. Identity after a lift (stale gas), the lift after identity (stale
// carried voxels), a smaller box (reallocated), then no labels (their output released).
TEST_F(WarpCpu, ASeriesOfWarpsGivesWhatFreshWarpsGive) {
  const WarpCase c = make_warp_case(grid_of({24, 20, 16}, {0.8, 0.8, 1.6}, rotation(25, Vec3(1, 0, 1))), 4, 17);
  const WarpMesh lift = make_warp_mesh(c.mesh, displacement_of(c, [&](const Vec3& x) {
    return Vec3(x + Vec3(0.5 * std::sin(x[1] / 4.0), 2.5 * std::cos(x[0] / 6.0), 1.2));
  }));
  const WarpMesh identity = make_warp_mesh(c.mesh, std::vector<Vec3>(std::size_t(c.mesh.node_count()), Vec3::Zero()));
  WarpSource no_labels = c.source();
  no_labels.labels = nullptr;
  struct Step {
    const WarpMesh* mesh;
    WarpBox box;
    WarpSource src;
  };
  const Step steps[] = {{&lift, c.whole(), c.source()}, {&identity, c.whole(), c.source()},
                        {&lift, c.whole(), c.source()}, {&lift, WarpBox{{2, 3, 1}, {19, 15, 13}}, c.source()},
                        {&identity, c.whole(), no_labels}};
  WarpSeries series;
  int n_step = 0;
  for (const Step& s : steps) {
    SCOPED_TRACE("step " + std::to_string(n_step++));
    const WarpResult fresh = warp_cpu(*s.mesh, s.src, s.box, options());
    const WarpResult& again = series.warp("cpu", *s.mesh, s.src, s.box, options());
    expect_same_bits(again, fresh);
    EXPECT_EQ(again.carried_voxels, fresh.carried_voxels);
    EXPECT_EQ(again.gas_voxels, fresh.gas_voxels);
    EXPECT_EQ(again.kept_voxels, fresh.kept_voxels);
    EXPECT_EQ(again.labels.empty(), s.src.labels == nullptr);
  }
  EXPECT_EQ(series.result().labels.capacity(), 0u) << "labels switched off, their memory still held";
  EXPECT_GT(warp_cpu(lift, c.source(), c.whole(), options()).gas_voxels, 0);
}

// The reference scatters the tetrahedra of one rest cube together, at most 8 to a group. Declaring
// the whole grid one cube puts every tetrahedron of a part into one key, so groups of 8 consecutive
// indices span the mesh and overlap everywhere: no tetrahedron may be lost and no value change. Same
// voxels carried, same labels; HU within 1e-3 (the rows start from other corners, so source points
// differ by rounding, ~1e-13 voxel). Voxels carried by none may differ: the rest space is now the
// whole grid (gas, not kept). (Groups visited against the index order: WarpClVsCpu's reversed trial.)
TEST_F(WarpCpu, GroupingTheTetrahedraLosesNothing) {
  const WarpCase c = make_warp_case(grid_of({24, 20, 16}, {0.8, 0.8, 1.6}, rotation(-15, Vec3(0, 1, 1))), 4, 16);
  auto u = displacement_of(c, [&](const Vec3& x) {
    return Vec3(x + Vec3(1.5 * std::sin(x[1] / 5.0), 1.0 * std::cos(x[0] / 4.0), 0.8 * std::sin(x[2] / 3.0)));
  });
  const WarpMesh by_cube = make_warp_mesh(c.mesh, u);
  WarpMesh one_cube = by_cube;
  one_cube.cube_voxels = 24;
  one_cube.cubes = {1, 1, 1};
  one_cube.cube_meshed = {1};
  const WarpResult a = warp_cpu(by_cube, c.source(), c.whole(), options());
  const WarpResult b = warp_cpu(one_cube, c.source(), c.whole(), options());
  int64_t carried = 0, differ = 0;
  double max_hu = 0;
  for (std::size_t n = 0; n < a.outcome.size(); ++n) {
    const bool in_a = a.outcome[n] == WarpOutcome::Carried, in_b = b.outcome[n] == WarpOutcome::Carried;
    if (!in_a && !in_b) continue;
    ++carried;
    differ += in_a != in_b || a.labels[n] != b.labels[n];
    max_hu = std::max(max_hu, double(std::abs(a.ct_hu[n] - b.ct_hu[n])));
  }
  EXPECT_EQ(differ, 0);
  EXPECT_LE(max_hu, 1e-3);
  EXPECT_GT(carried, 1000);
  EXPECT_GT(by_cube.tet_count(), 8 * 2);
}

// A box inside the working grid (the CT inside the roles' padding): the output is the box's voxels
// of the whole-grid result, nothing shifted. Compared bit for bit.
TEST_F(WarpCpu, OutputBoxIsTheSameVoxelsAsTheWholeGrid) {
  const WarpCase c = make_warp_case(grid_of({24, 24, 16}, {1.0, 1.0, 1.0}, Mat3::Identity()), 4, 16);
  const WarpMesh m = make_warp_mesh(c.mesh, displacement_of(c, [](const Vec3& x) {
    return Vec3(x + Vec3(0.3 * std::sin(x[2]), 0.7, -0.2 * x[0] / 24.0));
  }));
  const WarpResult whole = warp_cpu(m, c.source(), c.whole(), options());
  const WarpBox box{{3, 2, 1}, {17, 19, 13}};
  const WarpResult part = warp_cpu(m, c.source(), box, options());
  int64_t bad = 0;
  for (int64_t k = 0; k < 13; ++k)
    for (int64_t j = 0; j < 19; ++j)
      for (int64_t i = 0; i < 17; ++i) {
        const int64_t o = i + 17 * (j + 19 * k), w = c.grid.linear_index(i + 3, j + 2, k + 1);
        bad += part.ct_hu[o] != whole.ct_hu[w] || part.labels[o] != whole.labels[w] || part.outcome[o] != whole.outcome[w];
      }
  EXPECT_EQ(bad, 0);
}

// Points through the deformation (point_map.h): an affine deformation maps any point inside the
// meshes by the affine map and back (1e-9 mm: double rounding over ~30 mm); points outside every
// tetrahedron are not carried and come back unchanged.
TEST_F(WarpCpu, PointMapFollowsAnAffineDeformationBothWays) {
  const WarpCase c = make_warp_case(grid_of({32, 28, 24}, {0.7, 0.9, 1.3}, rotation(20, Vec3(1, 2, 3))), 4, 17);
  const Mat3 M = rotation(4, Vec3(1, 0, 1)) * Vec3(1.03, 1.0, 0.98).asDiagonal();
  const Vec3 b(0.8, 1.7, -0.6);
  const WarpMesh m = make_warp_mesh(c.mesh, displacement_of(c, [&](const Vec3& x) { return Vec3(M * x + b); }));
  const PointMap map(m, c.roles.data());
  const auto parts = cube_parts(c.mesh);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> any(0.0, 1.0);
  int tried = 0;
  while (tried < 200) {
    const Vec3 p(any(rng) * 31, any(rng) * 27, any(rng) * 23);
    if (!parts_at(c.mesh, parts, p)) continue;
    ++tried;
    const Vec3 mm = c.grid.to_world(p);
    const MappedPoint fwd = map.to_deformed(mm);
    ASSERT_TRUE(fwd.carried) << p.transpose();
    EXPECT_LE((fwd.point_mm - c.grid.to_world(M * p + b)).norm(), 1e-9);
    const MappedPoint back = map.to_original(fwd.point_mm);
    ASSERT_TRUE(back.carried);
    EXPECT_LE((back.point_mm - mm).norm(), 1e-9);
  }
  const Vec3 outside = c.grid.to_world(Vec3(0.2, 0.2, 0.2));   // a corner: air, never meshed
  const MappedPoint o = map.to_deformed(outside);
  EXPECT_FALSE(o.carried);
  EXPECT_EQ(o.point_mm, outside);
}

// The point map and the image warp agree: every carried voxel centre, mapped to the original frame,
// lands where the warp sampled it (its CT value there within 1e-3 HU, float rounding), on a smooth
// random deformation with separated wall and viscera.
TEST_F(WarpCpu, PointMapAgreesWithTheImageWarp) {
  const WarpCase c = make_warp_case(grid_of({24, 24, 16}, {0.9, 0.9, 1.8}, rotation(10, Vec3(1, 0, 0))), 4, 18);
  std::vector<Vec3> u(std::size_t(c.mesh.node_count()));
  for (int64_t n = 0; n < c.mesh.node_count(); ++n) {
    const Vec3 x = c.grid.to_index(1e3 * c.mesh.rest_m[n]);
    const Vec3 lift = c.mesh.node_part[n] == Part::Wall ? Vec3(0, 2.0 + std::sin(x[0] / 4.0), 0) : Vec3(0, -0.6, 0.3);
    u[std::size_t(n)] = 1e-3 * (c.index_to_mm() * lift);
  }
  const WarpMesh m = make_warp_mesh(c.mesh, u);
  const WarpResult r = warp_cpu(m, c.source(), c.whole(), options());
  const PointMap map(m, c.roles.data());
  int64_t checked = 0;
  double worst = 0.0;
  for (int64_t n = 0; n < c.grid.voxel_count(); ++n) {
    if (r.outcome[n] != WarpOutcome::Carried) continue;
    const Vec3 p(double(n % 24), double((n / 24) % 24), double(n / (24 * 24)));
    const MappedPoint back = map.to_original(c.grid.to_world(p));
    ASSERT_TRUE(back.carried) << p.transpose();
    worst = std::max(worst, std::abs(trilinear(c, c.grid.to_index(back.point_mm)) - double(r.ct_hu[n])));
    ++checked;
  }
  EXPECT_GT(checked, 1000);
  EXPECT_LE(worst, 1e-3);
}

// A hand-built mesh whose rest-space table stops short of the grid would be read past its end by both warps (they
// index it without checks, per voxel): check_warp_mesh refuses it at the door, naming the axis; so do broken ids.
TEST_F(WarpCpu, MeshesThatBreakTheIndexingAreRefusedBeforeWarping) {
  const WarpCase c = make_warp_case(grid_of({24, 24, 16}, {0.75, 0.75, 1.5}, Vec3(-1, -1, 1).asDiagonal()), 4, 11);
  const WarpMesh good = make_warp_mesh(c.mesh, std::vector<Vec3>(std::size_t(c.mesh.node_count()), Vec3::Zero()));
  EXPECT_NO_THROW(check_warp_mesh(good));

  WarpMesh short_table = good;
  short_table.cubes[0] -= 1;
  short_table.cube_meshed.resize(std::size_t(short_table.cubes[0] * short_table.cubes[1] * short_table.cubes[2]));
  try {
    warp_cpu(short_table, c.source(), c.whole(), options());
    ADD_FAILURE() << "a rest-space table one cube short was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("axis 0"), std::string::npos) << e.what();
  }

  WarpMesh bad_id = good;
  bad_id.tets[0][2] = int32_t(bad_id.rest_ijk.size());
  EXPECT_THROW(warp_cpu(bad_id, c.source(), c.whole(), options()), std::invalid_argument);
}
