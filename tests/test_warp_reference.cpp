// The plain reference of the image warp (host/warp/warp_reference.cpp) against closed forms, and the
// fast CPU warp (host/warp/warp_cpu.cpp) against the reference:
//  - Identity: the input bit for bit. Affine map: analytic resampling within 1e-3 HU, no cracks,
//    labels exact away from half-voxel ties (the same truths test_warp_cpu.cpp holds warp_cpu to).
//  - Whole-voxel translation: warp_cpu equals the reference bit for bit (exact by construction).
//  - Smooth random deformations, seeded, at two cube sizes, with wall and viscera separating and
//    pressing into each other, tetrahedra numbered both ways: where both carry a voxel the CT
//    agrees within 2e-4 HU (both in double; warp_cpu adds its source point up along the row, the
//    reference evaluates it per voxel: ~1e-12 voxel apart, which the float result hides but for
//    an ulp, 1.2e-4 HU at 1500 HU); outcome and label equal at every voxel: the tie bands of the
//    float32 kernel's test (measured_tie) are 10^7 times wider than the two differ, so no voxel of
//    these trials lies in one, and none may differ.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "core/progress.h"
#include "warp/warp.h"
#include "warp_test_support.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

WarpOptions options() { return warp_test_options(); }
Geometry oblique_grid() { return oblique_test_grid(); }

class WarpReference : public QuietWarpTest {};

}  // namespace

TEST_F(WarpReference, IdentityReturnsTheInputBitForBit) {
  const WarpCase c = make_warp_case(oblique_grid(), 4, 41);
  const WarpMesh m = make_warp_mesh(c.mesh, std::vector<Vec3>(std::size_t(c.mesh.node_count()), Vec3::Zero()));
  const WarpResult r = warp_reference(m, c.source(), c.whole(), options());
  ASSERT_EQ(r.ct_hu.size(), c.ct.size());
  EXPECT_EQ(std::memcmp(r.ct_hu.data(), c.ct.data(), c.ct.size() * sizeof(float)), 0);
  EXPECT_EQ(r.labels, c.labels);
  EXPECT_EQ(r.gas_voxels, 0);
  EXPECT_GT(r.carried_voxels, 0);
  EXPECT_EQ(r.carried_voxels + r.kept_voxels, c.grid.voxel_count());
}

TEST_F(WarpReference, AffineMatchesAnalyticResamplingWithNoCracks) {
  const AffineCase a = affine_case();
  const WarpResult r = warp_reference(a.mesh, a.c.source(), a.c.whole(), options());
  expect_affine_truth(a, r, 1e-6, 1e-3);
}

TEST_F(WarpReference, TheFastCpuWarpEqualsItOnAWholeVoxelTranslationBitForBit) {
  const WarpCase c = make_warp_case(oblique_grid(), 4, 42);
  const WarpMesh m = make_warp_mesh(c.mesh, uniform_displacement(c, Vec3(-2, 3, 1)));
  const WarpResult ref = warp_reference(m, c.source(), c.whole(), options());
  const WarpResult fast = warp_cpu(m, c.source(), c.whole(), options());
  expect_same_bits(ref, fast);
  EXPECT_GT(ref.gas_voxels, 0);
  EXPECT_GT(ref.carried_voxels, 0);
}

TEST_F(WarpReference, TheFastCpuWarpEqualsItOnRandomDeformationsExceptAtMeasuredTies) {
  struct Trial {
    uint32_t seed;
    CubeVoxels cube;
    double toward;          // > 0: wall and viscera press into each other (overlapping tetrahedra)
    bool reversed = false;  // tetrahedra numbered last cube first: owners, not visiting order, decide
  };
  // {4, 4, 2} and {3, 4, 2}: cubes of per-axis voxel counts, near-cubic on the grid's 0.8 × 0.8 × 1.6 mm voxels
  // (core/cube_voxels.h), and one lopsided.
  for (const Trial trial : {Trial{51, 4, 0.0}, Trial{52, 3, 0.0}, Trial{53, 4, 1.6}, Trial{54, 3, 1.6, true},
                            Trial{55, {4, 4, 2}, 0.0}, Trial{56, {3, 4, 2}, 1.6, true}}) {
    SCOPED_TRACE("seed " + std::to_string(trial.seed) + ", cube " + trial.cube.text());
    const WarpCase c = make_warp_case(oblique_grid(), trial.cube, trial.seed);
    const WarpMesh m = random_warp_mesh(c, trial.seed, trial.toward, trial.reversed);
    const WarpBox box{{1, 2, 1}, {22, 21, 18}};   // like a CT inside its padding
    const WarpResult ref = warp_reference(m, c.source(), box, options());
    const WarpResult fast = warp_cpu(m, c.source(), box, options());
    const WarpComparison cmp = compare_warps(ref, fast, m, box);
    EXPECT_GT(cmp.both_carried, 2000);
    EXPECT_GT(ref.gas_voxels, 0);
    EXPECT_LE(cmp.worst_hu, 2e-4) << "max CT difference (HU)";
    EXPECT_EQ(cmp.untied, 0) << "voxels whose outcome or label differ without a tie";
    EXPECT_EQ(cmp.ties, 0) << "voxels whose outcome or label differ, excused as ties";
    std::printf("seed %u: %lld voxels carried by both, max |dHU| %.2e, %lld tie mismatches\n", trial.seed,
                (long long)cmp.both_carried, cmp.worst_hu, (long long)cmp.ties);
  }
}
