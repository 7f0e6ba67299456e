// The chest beyond the cranial cut, as the scene sizes it (Scene::thorax_compliance_m3_per_pa,
// build_scene_mesh): the lungs' compliance C less the share of their volume V = K C the CT shows, K the
// lungs' bulk modulus E / 3(1 − 2ν). A block of aerated wall (−800 HU, no label: lung to the material)
// 80 × 80 × 40 mm, 256 ml, cut by the grid's top slice:
//   - at the default lung (E 1.0 kPa, ν 0.40: V = 2.04 L) the top face opens onto the chest with
//     C (1 − 0.256 / 2.04), within 1e-9 of that closed form;
//   - with lungs so soft that their whole volume is in view (E 0.1 kPa: V = 0.20 L < 0.256 L) no
//     compliance is left beyond the cut: the face slides, as without the chest, and nothing is left
//     open with a compliance of zero (which the force field refuses).
#include <gtest/gtest.h>

#include <vector>

#include "core/units.h"
#include "pipeline/scene_stages.h"
#include "scene/scene.h"

using namespace pneumo;

namespace {

constexpr int64_t kSide = 40, kSlices = 20;   // 2 mm voxels
constexpr double kVoxelMm = 2.0;

struct LungBlock {
  Geometry g;
  std::vector<Role> role;
  std::vector<float> hu;
  VoxelRoles view() const {
    VoxelRoles v{g, role.data(), nullptr, hu.data()};
    return v;
  }
};

LungBlock lung_block() {
  LungBlock b;
  b.g.dims = {kSide + 4, kSide + 4, kSlices};
  b.g.spacing_mm = Vec3(kVoxelMm, kVoxelMm, kVoxelMm);
  b.role.assign(std::size_t(b.g.voxel_count()), Role::Other);
  b.hu.assign(b.role.size(), -1000.0f);
  for (int64_t k = 0; k < kSlices; ++k)
    for (int64_t j = 2; j < kSide + 2; ++j)
      for (int64_t i = 2; i < kSide + 2; ++i) {
        const std::size_t v = std::size_t(b.g.linear_index(i, j, k));
        b.role[v] = Role::Wall;
        b.hu[v] = -800.0f;
      }
  return b;
}

Scene chest_scene(double lung_young_kpa) {
  return parse_scene(nlohmann::json{{"material", {{"model", "fem-neohookean"},
                                                  {"thorax_compliance_l_per_cmh2o", 0.12},
                                                  {"lung_young_kpa", lung_young_kpa}}},
                                    {"mesh", {{"cube_voxels", 2}}}},
                     "");
}

}  // namespace

TEST(ThoraxCompliance, TheChestBeyondTheCutIsTheLungsComplianceLessTheShareInView) {
  const LungBlock b = lung_block();
  const Mesh m = build_scene_mesh(b.view(), chest_scene(1.0));
  ASSERT_FALSE(m.thorax_node.empty());
  const double c = units::l_per_cmh2o_to_m3_per_pa(0.12);
  const double bulk_pa = 1.0e3 / (3.0 * (1.0 - 2.0 * 0.40));
  const double in_view_m3 = double(kSide * kSide * kSlices) * 8e-9;
  const double expected = c * (1.0 - in_view_m3 / (bulk_pa * c));
  EXPECT_NEAR(m.thorax_compliance_m3_per_pa, expected, 1e-9 * expected);
  EXPECT_GT(expected, 0.8 * c);
}

TEST(ThoraxCompliance, LungsWhollyInViewLeaveNoChestAndTheCutSlides) {
  const LungBlock b = lung_block();
  const Mesh m = build_scene_mesh(b.view(), chest_scene(0.1));
  EXPECT_TRUE(m.thorax_node.empty());
  EXPECT_EQ(m.thorax_compliance_m3_per_pa, 0.0);
  int64_t top_held = 0;
  for (int64_t n = 0; n < m.node_count(); ++n)
    top_held += m.node_lattice[std::size_t(n)][2] == kSlices / 2 && m.hold[std::size_t(n)] == kHoldZ;
  EXPECT_GT(top_held, 100);
}
