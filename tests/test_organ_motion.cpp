// Where each labelled structure went (pipeline/organ_motion.h), against what a known motion gives:
// a block of label 5 moved by whole voxels shifts its centroid by exactly that many millimetres and
// keeps its volume; a block doubled along one axis on a grid of half the spacing there keeps its
// centroid and doubles its volume (+100 %); the cavity's label, labels not asked for and labels under
// min_ml are left out; the tissue's own change is the mean of J − 1 over the voxels at rest.
#include <gtest/gtest.h>

#include <vector>

#include "pipeline/organ_motion.h"

using namespace pneumo;

namespace {

Geometry grid(const Vec3& spacing) {
  Geometry g;
  g.dims = {20, 20, 20};
  g.spacing_mm = spacing;
  g.origin_mm = Vec3(-10, 4, 100);
  return g;
}

void paint(std::vector<uint16_t>& v, const Geometry& g, Index3 lo, Index3 hi, uint16_t id) {
  for (int64_t k = lo[2]; k <= hi[2]; ++k)
    for (int64_t j = lo[1]; j <= hi[1]; ++j)
      for (int64_t i = lo[0]; i <= hi[0]; ++i) v[std::size_t(g.linear_index(i, j, k))] = id;
}

}  // namespace

TEST(OrganMotion, AMovedBlockShiftsByItsMotionAndKeepsItsVolume) {
  const Geometry g = grid(Vec3(2, 2, 3));
  std::vector<uint16_t> rest(std::size_t(g.voxel_count()), 0), moved = rest;
  paint(rest, g, {2, 2, 2}, {7, 8, 9}, 5);
  paint(moved, g, {4, 1, 7}, {9, 7, 14}, 5);   // +2, −1, +5 voxels
  paint(rest, g, {13, 13, 13}, {17, 17, 17}, 250);      // 1.5 ml of gas, asked for and still left out
  paint(moved, g, {13, 13, 13}, {18, 18, 18}, 250);
  paint(rest, g, {0, 0, 0}, {9, 9, 0}, 3);   // 1.2 ml of a label not asked for
  const auto m = organ_motion(rest, g, moved, g, 250, {{5, "liver"}}, {5, 250});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].label, 5);
  EXPECT_EQ(m[0].name, "liver");
  EXPECT_DOUBLE_EQ(m[0].volume_ml, 6 * 7 * 8 * 12 / 1000.0);
  EXPECT_NEAR(m[0].volume_change, 0.0, 1e-12);
  EXPECT_NEAR((m[0].shift_mm - Vec3(4, -2, 15)).norm(), 0.0, 1e-9);
}

TEST(OrganMotion, ABlockStretchedOnAFinerGridDoublesItsVolumeAboutTheSameCentroid) {
  const Geometry coarse = grid(Vec3(2, 2, 2));
  Geometry fine = grid(Vec3(2, 1, 2));
  fine.dims = {20, 40, 20};
  fine.origin_mm = coarse.origin_mm - Vec3(0, 0.5, 0);   // the same box, voxels split along y
  std::vector<uint16_t> rest(std::size_t(coarse.voxel_count()), 0), stretched(std::size_t(fine.voxel_count()), 0);
  paint(rest, coarse, {5, 6, 5}, {9, 9, 9}, 7);          // y from 6 to 9: 4 coarse voxels, 8 mm
  paint(stretched, fine, {5, 8, 5}, {9, 23, 9}, 7);      // 16 fine voxels, 16 mm, about the same centre
  paint(rest, coarse, {0, 0, 0}, {0, 0, 0}, 9);          // 8 µl: under min_ml (0.1 ml here), left out
  EXPECT_TRUE(organ_motion(rest, coarse, stretched, fine, 250, {}, {}, 0.1).empty());   // no ids, none
  const auto m = organ_motion(rest, coarse, stretched, fine, 250, {}, {7, 9}, /*min_ml=*/0.1);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_TRUE(m[0].name.empty());
  EXPECT_NEAR(m[0].volume_change, 1.0, 1e-12);
  EXPECT_NEAR((m[0].shift_mm - Vec3(0, 0, 0)).norm(), 0.0, 1e-9) << m[0].shift_mm.transpose();
}

TEST(OrganMotion, TheTissuesVolumeChangeIsTheMeanOfJMinusOneOverItsVoxelsAtRest) {
  // A J field that is 0.8 on the block's lower half in x and unknown (nothing moves it) elsewhere:
  // the tissue loses a tenth of its volume, whatever the images say (here: unchanged). Without a J
  // field there is no tissue figure.
  const Geometry g = grid(Vec3(2, 2, 3));
  std::vector<uint16_t> rest(std::size_t(g.voxel_count()), 0);
  paint(rest, g, {2, 2, 2}, {9, 8, 9}, 5);   // x from 2 to 9: half the voxels below x = 6
  const JacobianAtFn half = [&g](int64_t voxel, const Vec3& mm) -> std::optional<double> {
    EXPECT_NEAR((g.to_world(Vec3(double(voxel % 20), double(voxel / 20 % 20), double(voxel / 400))) - mm).norm(), 0.0, 1e-9);
    return voxel % 20 < 6 ? std::optional<double>(0.8) : std::nullopt;
  };
  const auto m = organ_motion(rest, g, rest, g, 250, {}, {5}, 1.0, half);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_NEAR(m[0].volume_change, 0.0, 1e-12);
  ASSERT_TRUE(m[0].tissue_volume_change.has_value());
  EXPECT_NEAR(*m[0].tissue_volume_change, -0.1, 1e-12);
  EXPECT_FALSE(organ_motion(rest, g, rest, g, 250, {}, {5})[0].tissue_volume_change.has_value());
}
