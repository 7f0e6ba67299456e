// The chest above the diaphragm found on a CT without labels (anatomy/thorax.h) and what the roles
// make of it (auto_roles.h, rules 3b and 5c), on a synthetic trunk drawn in world millimetres:
// an elliptic body of soft tissue; two lungs inside an elliptic rib cage (−850 HU with ±60 HU of texture) above a diaphragm of
// two domes, highest at |x| = 70 mm (z = 110) and falling to z = 90 at the costophrenic recesses
// and beside the heart; the heart (soft tissue, as on a CT without contrast) on the central tendon
// at z = 90 between them; below, a stomach gas bubble (−1000 HU with ±15 HU of noise, 113 ml) and a
// small bowel bubble. What is checked is exact where the drawing decides it (which parts are lung)
// and otherwise bounded by a voxel (the heart's bottom lies under the surface interpolated between
// the lungs' medial bases by less than one).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "anatomy/body_mask.h"
#include "anatomy/thorax.h"
#include "roles/auto_roles.h"

using namespace pneumo;

namespace {

enum Part : uint8_t { kOutside, kTissue, kLung, kHeart, kStomachGas, kBowelGas };

double texture(const Vec3& p, double amplitude) {   // deterministic, in [−amplitude, amplitude]
  const double s = std::sin(p[0] * 12.9898 + p[1] * 78.233 + p[2] * 37.719) * 43758.5453;
  return amplitude * (2.0 * (s - std::floor(s)) - 1.0);
}

double dome_z(double x) { return 110.0 - 0.008 * (std::abs(x) - 70.0) * (std::abs(x) - 70.0); }

Part part_at(const Vec3& p, bool with_lungs) {
  const double x = p[0], y = p[1], z = p[2];
  if ((x / 140.0) * (x / 140.0) + (y / 95.0) * (y / 95.0) > 1.0) return kOutside;
  const Vec3 h = (p - Vec3(0, 0, 130)).cwiseQuotient(Vec3(40, 45, 40));
  if (with_lungs && h.squaredNorm() <= 1.0) return kHeart;
  const bool in_ribcage = (x / 125.0) * (x / 125.0) + (y / 80.0) * (y / 80.0) <= 1.0;
  if (with_lungs && in_ribcage && std::abs(x) >= 20 && y > -70 && y < 60 && z >= dome_z(x)) return kLung;
  if ((p - Vec3(50, 30, 50)).norm() <= 30.0) return kStomachGas;
  if ((p - Vec3(-60, 40, 20)).norm() <= 8.0) return kBowelGas;
  return kTissue;
}

float hu_of(Part part, const Vec3& p) {
  switch (part) {
    case kOutside: return -1000.0f;
    case kLung: return float(-850.0 + texture(p, 60.0));
    case kStomachGas:
    case kBowelGas: return float(-1000.0 + texture(p, 15.0));
    default: return float(40.0 + texture(p, 10.0));
  }
}

struct Trunk {
  Geometry g;
  std::vector<Part> part;
  std::vector<float> hu;
  std::vector<uint8_t> body;
};

/// 3 mm voxels over x ∈ [−150, 150], y ∈ [−105, 105], z ∈ [−15, 165] mm; `flipped`: stored LPS with the
/// slices running from head to feet, the same trunk in the same world.
Trunk trunk(bool flipped = false, bool with_lungs = true) {
  Trunk t;
  t.g.dims = {100, 70, 60};
  t.g.spacing_mm = Vec3(3, 3, 3);
  t.g.origin_mm = Vec3(-148.5, -103.5, -13.5);
  if (flipped) {
    t.g.direction = Vec3(-1, -1, -1).asDiagonal();
    t.g.origin_mm = Vec3(148.5, 103.5, 163.5);
  }
  const int64_t n = t.g.voxel_count();
  t.part.resize(std::size_t(n));
  t.hu.resize(std::size_t(n));
  for (int64_t k = 0; k < t.g.dims[2]; ++k)
    for (int64_t j = 0; j < t.g.dims[1]; ++j)
      for (int64_t i = 0; i < t.g.dims[0]; ++i) {
        const Vec3 p = t.g.to_world(Vec3(double(i), double(j), double(k)));
        const int64_t v = t.g.linear_index(i, j, k);
        t.part[v] = part_at(p, with_lungs);
        t.hu[v] = hu_of(t.part[v], p);
      }
  t.body = body_mask(t.hu.data(), t.g, -500.0);
  return t;
}

int64_t count(const Trunk& t, const std::vector<uint8_t>& mask, Part p) {
  int64_t c = 0;
  for (std::size_t v = 0; v < mask.size(); ++v) c += mask[v] && t.part[v] == p;
  return c;
}
int64_t count(const Trunk& t, Part p) {
  int64_t c = 0;
  for (Part q : t.part) c += q == p;
  return c;
}

}  // namespace

TEST(Thorax, TheLungsAreFoundByDensityAndTheGasBelowIsNot) {
  const Trunk t = trunk();
  const Thorax th = find_thorax(t.hu.data(), t.body, t.g);
  EXPECT_EQ(th.lung_parts, 2);
  EXPECT_EQ(count(t, th.lungs, kLung), count(t, kLung));
  EXPECT_EQ(count(t, th.lungs, kStomachGas), 0);
  EXPECT_EQ(count(t, th.lungs, kBowelGas), 0);
  EXPECT_EQ(count(t, th.lungs, kTissue) + count(t, th.lungs, kHeart), 0);
  EXPECT_NEAR(th.lung_ml, double(count(t, kLung)) * 27.0 / 1000.0, 1e-9);
}

TEST(Thorax, TheChestHoldsTheHeartAndNothingBelowTheDomes) {
  const Trunk t = trunk();
  const Thorax th = find_thorax(t.hu.data(), t.body, t.g);
  // The heart's bottom (z = 90) lies under the surface interpolated between the lungs' medial bases
  // (z ≥ 90 at |x| = 20) by less than a voxel.
  EXPECT_GE(double(count(t, th.chest, kHeart)), 0.95 * double(count(t, kHeart)));
  for (int64_t k = 0; k < t.g.dims[2]; ++k) {
    const double z = t.g.to_world(Vec3(0, 0, double(k)))[2];
    if (z >= 87.0) continue;   // the lowest lung voxel's centre is at 88.5 mm (the recess at |x| = 119)
    for (int64_t j = 0; j < t.g.dims[1]; ++j)
      for (int64_t i = 0; i < t.g.dims[0]; ++i)
        ASSERT_FALSE(th.chest[t.g.linear_index(i, j, k)]) << "chest at z = " << z << " mm";
  }
  // A label naming the heart puts all of it in the chest.
  std::vector<uint8_t> heart(t.part.size());
  for (std::size_t v = 0; v < heart.size(); ++v) heart[v] = t.part[v] == kHeart;
  const Thorax labelled = find_thorax(t.hu.data(), t.body, t.g, &heart);
  EXPECT_EQ(count(t, labelled.chest, kHeart), count(t, kHeart));
}

TEST(Thorax, TheSameChestOnAGridStoredTheOtherWayRound) {
  const Trunk ras = trunk(false), lps = trunk(true);
  const Thorax a = find_thorax(ras.hu.data(), ras.body, ras.g), b = find_thorax(lps.hu.data(), lps.body, lps.g);
  EXPECT_EQ(a.lung_parts, b.lung_parts);
  EXPECT_DOUBLE_EQ(a.chest_ml, b.chest_ml);
  for (int64_t k = 0; k < ras.g.dims[2]; ++k)
    for (int64_t j = 0; j < ras.g.dims[1]; ++j)
      for (int64_t i = 0; i < ras.g.dims[0]; ++i)
        ASSERT_EQ(a.chest[ras.g.linear_index(i, j, k)],
                  b.chest[lps.g.linear_index(ras.g.dims[0] - 1 - i, ras.g.dims[1] - 1 - j, ras.g.dims[2] - 1 - k)]);
}

TEST(Thorax, NoLungInViewNoChest) {
  const Trunk t = trunk(false, /*with_lungs=*/false);
  const Thorax th = find_thorax(t.hu.data(), t.body, t.g);
  EXPECT_EQ(th.lung_parts, 0);
  EXPECT_EQ(th.chest_ml, 0.0);
}

TEST(Thorax, NoViscusTouchesALungOrTheHeartAndTheRuleIsWhatKeepsThemApart) {
  // The automatic roles without labels: lungs and heart fixed, a diaphragm of wall under them, so no
  // viscera voxel is 6-adjacent to either (the gas opens only between wall and viscera). Without the
  // rule (auto_thorax false) the heart and the lungs' hole-filled parenchyma are viscera.
  const Trunk t = trunk();
  auto viscera_touching_chest = [&](const std::vector<Role>& role) {
    int64_t c = 0;
    const Index3 d = t.g.dims;
    for (int64_t k = 0; k < d[2]; ++k)
      for (int64_t j = 0; j < d[1]; ++j)
        for (int64_t i = 0; i < d[0]; ++i) {
          const int64_t v = t.g.linear_index(i, j, k);
          if (role[v] != Role::Viscera) continue;
          const int64_t nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
          for (const auto& q : nb) {
            if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= d[0] || q[1] >= d[1] || q[2] >= d[2]) continue;
            const Part p = t.part[t.g.linear_index(q[0], q[1], q[2])];
            c += p == kLung || p == kHeart;
          }
        }
    return c;
  };
  RoleRules r;
  const std::vector<Role> role = auto_roles(r, t.g, t.hu.data(), nullptr, &t.body);
  EXPECT_EQ(viscera_touching_chest(role), 0);
  for (std::size_t v = 0; v < role.size(); ++v)
    if (t.part[v] == kLung || t.part[v] == kHeart) {
      ASSERT_TRUE(role[v] == Role::Fixed || role[v] == Role::Wall) << "voxel " << v << " is " << role_name(role[v]);
    }
  r.auto_thorax = false;
  const std::vector<Role> without = auto_roles(r, t.g, t.hu.data(), nullptr, &t.body);
  EXPECT_GT(viscera_touching_chest(without), 100);
}

TEST(Thorax, TheLungTissueHoldsItsVesselsAndNotTheHeart) {
  // A vessel 6 mm across (two voxels) runs through the left lung along y at x = −70, z = 130: the
  // closing by 6 mm makes it lung tissue; the heart, the tissue under the domes and the stomach's gas
  // are not; a labelled heart (2) stays out even where it touches the lung.
  Trunk t = trunk();
  int64_t vessel = 0;
  for (int64_t v = 0; v < t.g.voxel_count(); ++v) {
    if (t.part[std::size_t(v)] != kLung) continue;
    const Vec3 p = t.g.to_world(Vec3(double(v % t.g.dims[0]), double((v / t.g.dims[0]) % t.g.dims[1]),
                                     double(v / (t.g.dims[0] * t.g.dims[1]))));
    if (std::abs(p[0] + 70.0) < 3.1 && std::abs(p[2] - 130.0) < 1.6 && std::abs(p[1]) < 40.0) {
      t.hu[std::size_t(v)] = 40.0f;
      ++vessel;
    }
  }
  ASSERT_GT(vessel, 20);
  const Thorax th = find_thorax(t.hu.data(), t.body, t.g);
  int64_t vessel_in = 0;
  for (int64_t v = 0; v < t.g.voxel_count(); ++v)
    vessel_in += t.part[std::size_t(v)] == kLung && t.hu[std::size_t(v)] > 0.0f && th.lung_tissue[std::size_t(v)];
  EXPECT_EQ(vessel_in, vessel);
  EXPECT_EQ(count(t, th.lung_tissue, kLung), count(t, kLung));
  EXPECT_LT(count(t, th.lung_tissue, kHeart), count(t, kHeart) / 20);   // the closing reaches its rim only
  EXPECT_EQ(count(t, th.lung_tissue, kStomachGas), 0);
  std::vector<uint8_t> labelled(t.part.size());
  for (std::size_t v = 0; v < labelled.size(); ++v) labelled[v] = t.part[v] == kHeart ? 2 : 0;
  const Thorax with_heart = find_thorax(t.hu.data(), t.body, t.g, &labelled);
  EXPECT_EQ(count(t, with_heart.lung_tissue, kHeart), 0);
  EXPECT_EQ(count(t, with_heart.lung_tissue, kLung), count(t, kLung));
  // Asked for none (held lungs, the diaphragm metric): no closing, the rest the same.
  ThoraxOptions none;
  none.lung_closing_mm = 0.0;
  const Thorax bare = find_thorax(t.hu.data(), t.body, t.g, nullptr, none);
  EXPECT_TRUE(bare.lung_tissue.empty());
  EXPECT_EQ(bare.lungs, th.lungs);
  EXPECT_EQ(bare.chest, th.chest);
}

TEST(Thorax, CompliantLungsAreWallAndFixedLungsAreFixed) {
  // roles.compliant_lungs (the default): the lungs are wall, so the diaphragm can rise into them; the
  // heart stays fixed. Off: the lungs are fixed, as before.
  const Trunk t = trunk();
  RoleRules r;
  ASSERT_TRUE(r.compliant_lungs);
  const std::vector<Role> compliant = auto_roles(r, t.g, t.hu.data(), nullptr, &t.body);
  r.compliant_lungs = false;
  const std::vector<Role> fixed = auto_roles(r, t.g, t.hu.data(), nullptr, &t.body);
  int64_t lung = 0, lung_wall = 0, lung_fixed = 0, heart_fixed = 0, heart_inside = 0;
  for (std::size_t v = 0; v < t.part.size(); ++v) {
    if (t.part[v] == kLung) {
      ++lung;
      lung_wall += compliant[v] == Role::Wall;
      lung_fixed += fixed[v] == Role::Fixed;
    }
    if (t.part[v] == kHeart && fixed[v] == Role::Fixed) {
      ++heart_inside;
      heart_fixed += compliant[v] == Role::Fixed;
    }
  }
  EXPECT_EQ(lung_wall, lung);
  EXPECT_EQ(lung_fixed, lung);
  EXPECT_GT(heart_inside, 0);
  // The heart's rim the lungs' closing reaches becomes lung tissue; the rest stays fixed.
  EXPECT_GT(heart_fixed, heart_inside * 9 / 10);
}
