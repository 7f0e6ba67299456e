// Room for the wall to rise found on the CT (roles/auto_pad.h): the body's distance to the grid's
// edges, on any orientation, and the padding a scene that gives none gets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/progress.h"
#include "example_roles_support.h"
#include "io/volume_io.h"
#include "roles/auto_pad.h"
#include "anatomy/body_mask.h"

using namespace pneumo;

namespace {

/// An elliptic body (semi-axes 150 × 100 mm, centre `centre_mm`) on 4 × 5 × 5 mm voxels spanning
/// x −220…220, y −150…150 (anterior +y): `centre_mm` moves the skin towards one edge.
Volume body_ct(const Vec3& centre_mm, const Mat3& direction = Mat3::Identity()) {
  Geometry g;
  g.dims = {111, 61, 4};
  g.spacing_mm = Vec3(4, 5, 5);
  g.direction = direction;
  // The grid covers the same box in every orientation: its first voxel is the box's corner in world terms.
  const Vec3 lo(-220, -150, 0), hi(220, 150, 15);
  Vec3 corner = lo;
  for (int a = 0; a < 3; ++a)
    if (direction.col(a).sum() < 0) corner += (hi - lo).cwiseProduct(direction.col(a).cwiseAbs());
  g.origin_mm = corner;
  Volume v(g, VoxelType::Int16);
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        const Vec3 w = g.to_world(Vec3(double(i), double(j), double(k))) - centre_mm;
        const bool in = std::pow(w.x() / 150, 2) + std::pow(w.y() / 100, 2) <= 1.0;
        v.data<int16_t>()[g.linear_index(i, j, k)] = int16_t(in ? 40 : -1000);
      }
  return v;
}

/// The CT's HU as float32, as the roles read them.
Volume as_float(const Volume& ct) {
  Volume out(ct.geometry(), VoxelType::Float32);
  for (int64_t n = 0; n < ct.voxel_count(); ++n) out.data<float>()[n] = float(ct.value(n));
  return out;
}

/// The body of a CT as the automatic roles find it.
std::vector<uint8_t> body_of(const Volume& ct) { return body_mask(as_float(ct).data<float>(), ct.geometry(), -500.0); }

BodyClearance clearance_of(const Volume& ct) { return body_clearance(body_of(ct), ct.geometry()); }

}  // namespace

TEST(AutoPad, ClearanceIsTheBodysDistanceToEachEdgeInMillimetres) {
  // Centred: anterior skin at y = 100, grid edge at 150 (50 mm); sides at ±150 vs ±220 (70 mm).
  BodyClearance c = clearance_of(body_ct(Vec3(0, 0, 0)));
  EXPECT_NEAR(c.anterior_mm, 50.0, 5.0);
  EXPECT_NEAR(c.right_mm, 70.0, 4.0);
  EXPECT_NEAR(c.left_mm, 70.0, 4.0);
  // Moved 30 mm to the patient's right (+x) and 40 mm forward.
  c = clearance_of(body_ct(Vec3(30, 40, 0)));
  EXPECT_NEAR(c.anterior_mm, 10.0, 5.0);
  EXPECT_NEAR(c.right_mm, 40.0, 4.0);
  EXPECT_NEAR(c.left_mm, 100.0, 4.0);
}

TEST(AutoPad, AnLpsGridMeasuresTheSameSides) {
  // LPS: the first two voxel axes run towards the patient's left and back.
  const Mat3 lps = Vec3(-1, -1, 1).asDiagonal();
  const BodyClearance c = clearance_of(body_ct(Vec3(30, 40, 0), lps));
  EXPECT_NEAR(c.anterior_mm, 10.0, 5.0);
  EXPECT_NEAR(c.right_mm, 40.0, 4.0);
  EXPECT_NEAR(c.left_mm, 100.0, 4.0);
}

TEST(AutoPad, OnlySidesTheSceneLeavesUnsetAndTooCloseArePadded) {
  const Volume ct = body_ct(Vec3(30, 40, 0));   // anterior 10 mm, right 40 mm, left 100 mm
  const std::vector<uint8_t> body = body_of(ct);
  RoleRules r;
  r.source = RoleSource::Auto;
  PadMm p = resolved_pad_mm(r, &body, ct.geometry());
  EXPECT_EQ(p.anterior, kAutoPadMm);
  EXPECT_EQ(p.lateral, kAutoPadMm);   // the right side is 40 mm from its edge
  r.pad_lateral_mm = 0.0;             // the scene's word wins, 0 included
  p = resolved_pad_mm(r, &body, ct.geometry());
  EXPECT_EQ(p.anterior, kAutoPadMm);
  EXPECT_EQ(p.lateral, 0.0);
  // Room enough everywhere: nothing added.
  const Volume roomy = body_ct(Vec3(0, -45, 0));   // anterior 95 mm, sides 70 mm
  const std::vector<uint8_t> roomy_body = body_of(roomy);
  RoleRules automatic;
  automatic.source = RoleSource::Auto;
  p = resolved_pad_mm(automatic, &roomy_body, roomy.geometry());
  EXPECT_EQ(p.anterior, 0.0);
  EXPECT_EQ(p.lateral, 0.0);
  // Labels describe every voxel, air included: nothing is found or added.
  r = RoleRules{};
  r.source = RoleSource::Labels;
  p = resolved_pad_mm(r, nullptr, ct.geometry());
  EXPECT_EQ(p.anterior, 0.0);
  EXPECT_EQ(p.lateral, 0.0);
}

TEST(AutoPad, TheExampleCtsSkinIsWhereItsSceneSays) {
  // scenes/totalseg_example.json: "anterior skin 12 mm from the edge", so 60 mm is added in front and
  // at the sides (RolesRealCT.PaddedGridKeepsEveryVoxel checks the padded grid).
  PNEUMO_REQUIRE_REAL_CT();
  Progress::set_enabled(false);
  const BodyClearance c = clearance_of(read_volume(testing_support::example_ct_path()));
  EXPECT_NEAR(c.anterior_mm, 12.0, 3.0);
  EXPECT_LT(std::min(c.right_mm, c.left_mm), kAutoPadMm);
}
