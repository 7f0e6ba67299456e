// The wall's skin area (pipeline/skin_area.h) against what a known motion gives: a block of wall in
// air, 4 × 3 × 2 voxels of 2 × 3 × 4 mm (8 × 9 × 8 mm), has its six sides' area at rest; carried by
// a uniform scaling s every area grows by s² exactly, by a translation not at all; faces toward the
// padding outside the CT's box, or toward tissue left out inside the body, are no skin; corners the
// map does not carry stay put and are counted.
#include <gtest/gtest.h>

#include <vector>

#include "pipeline/skin_area.h"

using namespace pneumo;

namespace {

struct Block {
  Geometry g;
  std::vector<Role> role;
  std::vector<uint8_t> body;   // the block, and with `hollow` an air voxel of it, in the body
  VoxelRoles view(Index3 last = {-1, -1, -1}) const {
    VoxelRoles v{g, role.data()};
    v.ct_last = last;
    return v;
  }
};

/// Wall voxels i 2…5, j 2…4, k 2…3; with `hollow`, voxel (6, 3, 2) beside it is air inside the body
/// (tissue the roles left out), its face toward the block no skin.
Block block(bool hollow = false) {
  Block b;
  b.g.dims = {8, 7, 6};
  b.g.spacing_mm = Vec3(2, 3, 4);
  b.g.origin_mm = Vec3(-7, 12, 40);
  b.role.assign(std::size_t(b.g.voxel_count()), Role::Other);
  b.body.assign(b.role.size(), 0);
  for (int64_t k = 2; k <= 3; ++k)
    for (int64_t j = 2; j <= 4; ++j)
      for (int64_t i = 2; i <= 5; ++i) {
        b.role[std::size_t(b.g.linear_index(i, j, k))] = Role::Wall;
        b.body[std::size_t(b.g.linear_index(i, j, k))] = 1;
      }
  if (hollow) b.body[std::size_t(b.g.linear_index(6, 3, 2))] = 1;
  return b;
}

// Sides of the 8 × 9 × 8 mm block: 2(8·9 + 8·8 + 9·8) mm².
constexpr double kBlockMm2 = 2.0 * (8 * 9 + 8 * 8 + 9 * 8);

}  // namespace

TEST(SkinArea, ScaledBySGrowsBySSquaredAndMovedNotAtAll) {
  const Block b = block();
  const Vec3 centre(1.0, 20.0, 50.0);
  const SkinArea scaled = wall_skin_area(b.view(), b.body, [&](const Vec3& p, Vec3& q) {
    q = centre + 1.1 * (p - centre);
    return true;
  });
  EXPECT_EQ(scaled.faces, 2 * (4 * 3 + 4 * 2 + 3 * 2));
  EXPECT_NEAR(scaled.rest_mm2, kBlockMm2, 1e-9);
  EXPECT_NEAR(scaled.change(), 1.1 * 1.1 - 1.0, 1e-12);
  EXPECT_EQ(scaled.corners_not_carried, 0);
  const SkinArea moved = wall_skin_area(b.view(), b.body, [](const Vec3& p, Vec3& q) {
    q = p + Vec3(3, -2, 7);
    return true;
  });
  EXPECT_NEAR(moved.change(), 0.0, 1e-12);
}

TEST(SkinArea, UncarriedCornersStayWhereTheyWere) {
  // A map that carries nothing (and writes nonsense where it fails): every one of the block's 54
  // surface corners (5 × 4 × 3 less the 6 inside) stays put, so the area does not change.
  const Block b = block();
  const SkinArea none = wall_skin_area(b.view(), b.body, [](const Vec3& p, Vec3& q) {
    q = p + Vec3(50, 0, 0);
    return false;
  });
  EXPECT_EQ(none.corners_not_carried, 54);
  EXPECT_NEAR(none.change(), 0.0, 1e-12);
}

TEST(SkinArea, FacesTowardThePaddingOrTissueInsideTheBodyAreNoSkin) {
  // The CT's box ends at k = 3: the block's top (8 × 9 mm) faces the padding above it. A voxel of air
  // inside the body beside the block hides one 3 × 4 mm face.
  const Block b = block(/*hollow=*/true);
  auto still = [](const Vec3& p, Vec3& q) {
    q = p;
    return true;
  };
  EXPECT_NEAR(wall_skin_area(b.view(), b.body, still).rest_mm2, kBlockMm2 - 3 * 4, 1e-9);
  EXPECT_NEAR(wall_skin_area(b.view({-1, -1, 3}), b.body, still).rest_mm2, kBlockMm2 - 3 * 4 - 8 * 9, 1e-9);
}

TEST(SkinArea, TheAnteriorSkinIsWhatLiesWithinTheSectorOfStraightAheadOverTheViscera) {
  // The body's axis in each slice is the block's centroid (x 0, y 21 mm). Within 60° of anterior (+y)
  // lie the front (8 × 8 mm: 64 mm², 34° at most), the sides' front row (centres 4 mm aside and 3 mm
  // ahead: 53°; 2 sides × 2 slices × 3 × 4 mm = 48 mm²) and the top's and bottom's front row (1 or 3 mm
  // aside, 3 mm ahead: 45° at most; 2 × 4 × 2 × 3 mm = 48 mm²); the rows level with the axis (90°) and
  // behind it are out: 160 mm². A uniform scaling grows it by s², as the whole skin; a map that moves
  // only what lies behind y = 21 mm changes the whole skin and leaves the anterior skin alone.
  // Behind the block (j = 1) a row of viscera, except behind i = 2, where a bone voxel is: the skin in
  // front of that column lies over bone (one column of the front, 2 slices × 2 × 4 mm, and the left
  // side's front row, 2 × 3 × 4 mm, and the top's and bottom's, 2 × 2 × 3 mm, are out: 160 − 52 = 108 mm²).
  // The whole skin keeps everything but the block's back.
  Block b = block();
  for (int64_t k = 2; k <= 3; ++k)
    for (int64_t i = 2; i <= 5; ++i) {
      b.role[std::size_t(b.g.linear_index(i, 1, k))] = i == 2 ? Role::Fixed : Role::Viscera;
    }   // (the body mask stays the block's, so the axis does not move; the block's back is no skin now)
  const SkinArea scaled = wall_skin_area(b.view(), b.body, [](const Vec3& p, Vec3& q) {
    q = Vec3(1, 20, 50) + 1.2 * (p - Vec3(1, 20, 50));
    return true;
  });
  EXPECT_NEAR(scaled.anterior_rest_mm2, 108.0, 1e-9);
  EXPECT_NEAR(scaled.anterior_change(), 1.2 * 1.2 - 1.0, 1e-12);
  const SkinArea back = wall_skin_area(b.view(), b.body, [](const Vec3& p, Vec3& q) {
    q = p[1] < 21.0 ? Vec3(1.3 * p[0], p[1] - 2.0, p[2]) : p;
    return true;
  });
  EXPECT_GT(std::abs(back.change()), 0.01);
  EXPECT_NEAR(back.anterior_change(), 0.0, 1e-12);
  EXPECT_NEAR(wall_skin_area(b.view(), b.body, [](const Vec3& p, Vec3& q) { q = p; return true; }, 91.0).anterior_rest_mm2,
              108.0 + 2 * 12 + 2 * 3 * 6, 1e-9);   // past 90°: the rows level with the axis join, less the bone's column
}
