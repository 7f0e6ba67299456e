// One solve's deformation on another grid (warp_mesh.h warp_mesh_on_grid), what `pneumo validate
// view-resolution` applies to the same body imaged at three resolutions. Truths: on the mesh's own
// grid the warp is unchanged (same values, same outcomes); on a grid of half the spacing every node's
// rest and deformed world positions are the original's, and a voxel lies in the rest space exactly
// when the original voxel holding its centre did.
#include <gtest/gtest.h>

#include "warp/warp.h"
#include "warp_test_support.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

class WarpOnGrid : public QuietWarpTest {};

TEST_F(WarpOnGrid, OnItsOwnGridTheWarpIsUnchanged) {
  const AffineCase a = affine_case();
  const WarpMesh& m = a.mesh;
  const WarpMesh same = warp_mesh_on_grid(m, m.grid);
  const WarpResult r0 = warp_cpu(m, a.c.source(), a.c.whole(), warp_test_options());
  const WarpResult r1 = warp_cpu(same, a.c.source(), a.c.whole(), warp_test_options());
  ASSERT_EQ(r0.ct_hu.size(), r1.ct_hu.size());
  ASSERT_GT(r0.carried_voxels, 100);
  ASSERT_GT(r0.gas_voxels, 0);
  for (std::size_t v = 0; v < r0.ct_hu.size(); ++v) {
    ASSERT_EQ(r0.outcome[v], r1.outcome[v]) << v;
    ASSERT_NEAR(r0.ct_hu[v], r1.ct_hu[v], 1e-3) << v;
    ASSERT_EQ(r0.labels[v], r1.labels[v]) << v;
  }
}

TEST_F(WarpOnGrid, OnAFinerGridNodesAndRestSpaceKeepTheirPlace) {
  const AffineCase a = affine_case();
  const WarpMesh& m = a.mesh;
  Geometry fine = m.grid;
  fine.spacing_mm = m.grid.spacing_mm / 2;
  for (int ax = 0; ax < 3; ++ax) fine.dims[ax] = 2 * m.grid.dims[ax];
  // Fine voxel centres 0, 1 sit at coarse −¼, +¼: the fine origin is a quarter of a coarse voxel back.
  fine.origin_mm = m.grid.to_world(Vec3(-0.25, -0.25, -0.25));
  const WarpMesh f = warp_mesh_on_grid(m, fine);
  for (std::size_t n = 0; n < m.rest_ijk.size(); ++n) {
    ASSERT_LT((fine.to_world(f.rest_ijk[n]) - m.grid.to_world(m.rest_ijk[n])).norm(), 1e-9);
    ASSERT_LT((fine.to_world(f.deformed_ijk(int32_t(n))) - m.grid.to_world(m.deformed_ijk(int32_t(n)))).norm(), 1e-9);
  }
  int64_t inside = 0;
  for (int64_t k = 0; k < fine.dims[2]; ++k)
    for (int64_t j = 0; j < fine.dims[1]; ++j)
      for (int64_t i = 0; i < fine.dims[0]; ++i) {
        // Fine voxel 2c and 2c+1 lie in coarse voxel c.
        const bool expected = m.in_rest_space(i / 2, j / 2, k / 2);
        ASSERT_EQ(f.in_rest_space(i, j, k), expected) << i << " " << j << " " << k;
        inside += expected;
      }
  EXPECT_GT(inside, 1000);
  EXPECT_LT(inside, fine.voxel_count());
}

}  // namespace
