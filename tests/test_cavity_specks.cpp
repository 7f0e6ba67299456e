// Gas pockets below the size floor are filled from their surroundings (warp/cavity_specks.h).
#include <gtest/gtest.h>

#include "warp/cavity_specks.h"

namespace pneumo {
namespace {

TEST(CavitySpecks, SmallPiecesAreFilledFromTheirNeighboursAndTheCavityStays) {
  // Compared, on a 10×10×10 box of tissue (HU = 10·i, label 7) holding a 5×5×5 gas block (125 voxels), a single
  // gas voxel at (8,8,8) and a 2-voxel speck at (1,8,1)-(2,8,1), with a floor of 10 voxels: the block stays gas;
  // the single voxel takes its −i neighbour's HU (70) and label; the speck fills from the surface inward, each
  // of its voxels from its first non-gas neighbour in the order −i, +i, −j, …: (1,8,1) from (0,8,1), HU 0,
  // (2,8,1) from (3,8,1), HU 30. Counts: 2 pieces, 3 voxels; gas 128 → 125, carried +3. Exact.
  const Index3 dims{10, 10, 10};
  const int64_t n = 1000;
  auto at = [&](int64_t i, int64_t j, int64_t k) { return i + 10 * (j + 10 * k); };
  WarpResult r;
  r.ct_hu.resize(n);
  r.labels.assign(n, 7);
  r.outcome.assign(n, WarpOutcome::Carried);
  for (int64_t k = 0; k < 10; ++k)
    for (int64_t j = 0; j < 10; ++j)
      for (int64_t i = 0; i < 10; ++i) r.ct_hu[at(i, j, k)] = 10.0f * float(i);
  auto gas = [&](int64_t v) {
    r.outcome[v] = WarpOutcome::Gas;
    r.ct_hu[v] = -1000.0f;
    r.labels[v] = 250;
  };
  for (int64_t k = 2; k < 7; ++k)
    for (int64_t j = 2; j < 7; ++j)
      for (int64_t i = 2; i < 7; ++i) gas(at(i, j, k));
  gas(at(8, 8, 8));
  gas(at(1, 8, 1));
  gas(at(2, 8, 1));
  r.gas_voxels = 128;
  r.carried_voxels = n - 128;
  const SpeckFill f = fill_cavity_specks(r, dims, 10);
  EXPECT_EQ(f.pieces, 2);
  EXPECT_EQ(f.voxels, 3);
  EXPECT_EQ(r.gas_voxels, 125);
  EXPECT_EQ(r.carried_voxels, n - 125);
  EXPECT_EQ(r.outcome[at(4, 4, 4)], WarpOutcome::Gas);
  EXPECT_EQ(r.labels[at(4, 4, 4)], 250);
  EXPECT_EQ(r.ct_hu[at(8, 8, 8)], 70.0f);
  EXPECT_EQ(r.labels[at(8, 8, 8)], 7);
  EXPECT_EQ(r.ct_hu[at(1, 8, 1)], 0.0f);
  EXPECT_EQ(r.ct_hu[at(2, 8, 1)], 30.0f);
  EXPECT_EQ(r.outcome[at(2, 8, 1)], WarpOutcome::Carried);
  // A floor of 1 voxel (or 0) keeps every piece.
  gas(at(8, 8, 8));
  EXPECT_EQ(fill_cavity_specks(r, dims, 1).voxels, 0);
  EXPECT_EQ(r.outcome[at(8, 8, 8)], WarpOutcome::Gas);
}

}  // namespace
}  // namespace pneumo
