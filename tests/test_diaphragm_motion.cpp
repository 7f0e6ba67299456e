// The diaphragm's cranial shift (pipeline/diaphragm_motion.h) on a drawn block: lung over tissue with a
// dome, bowel gas below, and a carried map whose displacement is known in closed form; and on the
// small phantom, whose thorax holds lung bases, the heart and a labelled diaphragm, run as a new user
// would with compliant lungs (the default) and with fixed ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/volume_io.h"
#include "pipeline/diaphragm_motion.h"
#include "scene_run_support.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

struct Block {
  Geometry g;
  std::vector<Role> role;
  std::vector<float> hu;
  std::vector<uint8_t> body;
  std::vector<uint8_t> lungs;   // the lung (not the bowel gas): what anatomy/thorax.h would find
};

/// 2 mm voxels, 30 × 20 × 40: lung (−850 HU, wall) above z = 40 + 0.5·|x − 30| mm (a roof-shaped
/// base), tissue (40 HU, wall) under it, and a bowel gas pocket (−1000 HU, viscera) low in the block.
Block block(Role lung_role) {
  Block b;
  b.g.dims = {30, 20, 40};
  b.g.spacing_mm = Vec3(2, 2, 2);
  const int64_t n = b.g.voxel_count();
  b.role.assign(std::size_t(n), Role::Wall);
  b.hu.assign(std::size_t(n), 40.0f);
  b.body.assign(std::size_t(n), 1);
  b.lungs.assign(std::size_t(n), 0);
  for (int64_t k = 0; k < 40; ++k)
    for (int64_t j = 0; j < 20; ++j)
      for (int64_t i = 0; i < 30; ++i) {
        const Vec3 p = b.g.to_world(Vec3(double(i), double(j), double(k)));
        const int64_t v = b.g.linear_index(i, j, k);
        if (p[2] > 40.0 + 0.5 * std::abs(p[0] - 30.0)) {
          b.hu[v] = -850.0f;
          b.role[v] = lung_role;
          b.lungs[v] = 1;
        } else if ((p - Vec3(30, 20, 10)).norm() < 6.0) {
          b.hu[v] = -1000.0f;
          b.role[v] = Role::Viscera;
        }
      }
  return b;
}

}  // namespace

TEST(DiaphragmMotion, AUniformRiseIsMeasuredInEveryColumnUnderTheLungs) {
  // Every point carried 7 mm cranially: median and dome 7 mm, one column per (x, y) whose lung base
  // lies above tissue; the bowel gas below, no lung, gives no second base.
  const Block b = block(Role::Wall);
  const VoxelRoles roles{b.g, b.role.data(), nullptr, b.hu.data()};
  const DiaphragmMotion d = diaphragm_motion(roles, b.body, b.lungs, [](const Vec3& p, Vec3& q) {
    q = p + Vec3(0, 0, 7);
    return true;
  });
  // Columns whose lung reaches the lowest slice have no base in view: base z = 40 + |x − 30|/2 ≥ 40 > 0.
  EXPECT_EQ(d.columns, 30 * 20);
  EXPECT_NEAR(d.median_cranial_mm, 7.0, 1e-9);
  EXPECT_NEAR(d.dome_cranial_mm, 7.0, 1e-9);
}

TEST(DiaphragmMotion, TheDomeIsWhereItRoseMost) {
  // A rise that falls off from x = 30 mm: 10 mm at the centre, 0 at |x − 30| ≥ 25 mm. The median is the
  // rise of the median column, the dome its 95th percentile, both from the faces' own x.
  const Block b = block(Role::Fixed);
  const VoxelRoles roles{b.g, b.role.data(), nullptr, b.hu.data()};
  auto rise = [](double x) { return std::max(0.0, 10.0 * (1.0 - std::abs(x - 30.0) / 25.0)); };
  const DiaphragmMotion d = diaphragm_motion(roles, b.body, b.lungs, [&](const Vec3& p, Vec3& q) {
    q = p + Vec3(0, 0, rise(p[0]));
    return true;
  });
  std::vector<double> per_column;
  for (int i = 0; i < 30; ++i) per_column.push_back(rise(2.0 * i));
  std::sort(per_column.begin(), per_column.end());
  EXPECT_EQ(d.columns, 600);
  EXPECT_NEAR(d.median_cranial_mm, per_column[15], 1e-9);   // 20 columns of each x: the 300th of 600
  EXPECT_NEAR(d.dome_cranial_mm, per_column[28], 1e-9);     // the 570th of 600
  // Points the map does not carry are counted and left out.
  const DiaphragmMotion none = diaphragm_motion(roles, b.body, b.lungs, [](const Vec3&, Vec3&) { return false; });
  EXPECT_EQ(none.not_carried, none.columns);
  EXPECT_EQ(none.median_cranial_mm, 0.0);
}

namespace {

struct PhantomRun {
  int code = -1;
  std::string err;
  nlohmann::json metrics;
  int64_t gas_touching_lung_or_heart = 0;
};

/// `pneumo run` on the medium phantom (the demo's) with only its inputs, 12 mmHg and `roles`.
PhantomRun run_phantom(const ScratchDir& dir, const std::string& name, const nlohmann::json& roles) {
  nlohmann::json scene = {{"name", name}, {"load", {{"pressure_mmhg", 12}}}};
  scene["inputs"] = {{"ct", dir.file("ph/ct.nii.gz")}, {"labels", dir.file("ph/labels.nii.gz")},
                     {"label_names", dir.file("ph/label_names.csv")}};
  if (!roles.empty()) scene["roles"] = roles;
  const SceneRun r = run_scene(dir, name, scene);
  PhantomRun p;
  p.code = r.code;
  p.err = r.err;
  if (r.code != 0) return p;
  p.metrics = r.metrics;
  const std::string out = r.out;
  // Gas 6-adjacent to the lungs (11, 14) or the heart (51) in the deformed labels.
  const Volume lab = read_volume(out + "/deformed_labels.nii.gz");
  const int gas = p.metrics["warp"]["cavity_label"].get<int>();
  const Index3 d = lab.geometry().dims;
  for (int64_t k = 1; k + 1 < d[2]; ++k)
    for (int64_t j = 1; j + 1 < d[1]; ++j)
      for (int64_t i = 1; i + 1 < d[0]; ++i) {
        if (int(lab.value(i, j, k)) != gas) continue;
        const int64_t nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
        for (const auto& q : nb) {
          const int id = int(lab.value(q[0], q[1], q[2]));
          p.gas_touching_lung_or_heart += id == 11 || id == 14 || id == 51;
        }
      }
  return p;
}

}  // namespace

TEST(DiaphragmMotion, ThePhantomsDiaphragmRisesIntoCompliantLungs) {
  // With the lungs fixed the diaphragm cannot move (under 0.5 mm anywhere: the warp's sub-voxel
  // carry); with the lungs compliant (1 kPa, ν 0.40) it rises: 4.1 mm at its domes and 1.4 mm over the
  // median lung base at writing, where patients' rises 10–30 mm (Andersson et al. 2005, 7 patients at
  // 11–13 mmHg: docs/fidelity.md, "The diaphragm", says what holds it). The gas meets a lung or the
  // heart no more often than with the lungs held (5 voxel faces then, 3 now: where the 1.5 mm grid
  // cuts the drawn diaphragm to one voxel; on the small phantom's 4 mm grid the moving lungs break
  // that sheet in 61, docs/fidelity.md).
  ScratchDir dir;
  ASSERT_EQ(run_pneumo("-q phantom --size medium --out " + dir.file("ph")).code, 0);
  const PhantomRun compliant = run_phantom(dir, "compliant", nlohmann::json::object());
  const PhantomRun fixed = run_phantom(dir, "fixed", {{"compliant_lungs", false}});
  ASSERT_EQ(compliant.code, 0) << compliant.err;
  ASSERT_EQ(fixed.code, 0) << fixed.err;
  const double dome = compliant.metrics["diaphragm_dome_cranial_shift_mm"].get<double>();
  const double median = compliant.metrics["diaphragm_cranial_shift_mm"].get<double>();
  std::printf("phantom diaphragm: compliant lungs dome %.2f mm, median %.2f mm, gas on lung %lld faces; fixed dome "
              "%.2f mm, gas on lung %lld faces\n",
              dome, median, (long long)compliant.gas_touching_lung_or_heart,
              fixed.metrics["diaphragm_dome_cranial_shift_mm"].get<double>(), (long long)fixed.gas_touching_lung_or_heart);
  EXPECT_LT(std::abs(fixed.metrics["diaphragm_dome_cranial_shift_mm"].get<double>()), 0.5);
  EXPECT_GT(dome, 2.5);
  EXPECT_GT(median, 0.7);
  EXPECT_EQ(compliant.metrics["inverted_tetrahedra"].get<int>(), 0);
  EXPECT_LE(compliant.gas_touching_lung_or_heart, std::max<int64_t>(fixed.gas_touching_lung_or_heart, 5));
}
