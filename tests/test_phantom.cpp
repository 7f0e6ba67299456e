// The synthetic abdomen: grid and frame, determinism (including across thread counts), and anatomical
// plausibility (organ volumes, wall thickness, HU, gas, air in front of the body, the wall enclosing the cavity).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <unistd.h>

#include "core/error.h"
#include "core/progress.h"
#include "io/label_table.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"

namespace pneumo {
// gtest prints parameters with this (instead of their bytes).
void PrintTo(PhantomSize s, std::ostream* os) { *os << phantom_size_name(s); }

namespace {

// ---- shared generation (each size once per test binary) -----------------------------------------------------------
const Phantom& phantom(PhantomSize size) {
  static std::map<PhantomSize, Phantom> cache;
  auto it = cache.find(size);
  if (it == cache.end()) {
    Progress::set_enabled(false);
    it = cache.emplace(size, make_phantom(size)).first;
  }
  return it->second;
}

const PhantomLabel& label_named(const std::string& name) {
  for (const PhantomLabel& l : phantom_labels())
    if (l.name == name) return l;
  throw std::logic_error("no label " + name);
}
int id_of(const std::string& name) { return label_named(name).id; }

std::map<int, int64_t> label_counts(const Phantom& p) {
  std::map<int, int64_t> c;
  const uint8_t* l = p.labels.data<uint8_t>();
  for (int64_t n = 0; n < p.labels.voxel_count(); ++n) ++c[l[n]];
  return c;
}

double voxel_ml(const Phantom& p) { return p.labels.geometry().spacing_mm.prod() / 1000.0; }

std::set<int> ids_with_role(Role role) {
  std::set<int> s;
  for (const PhantomLabel& l : phantom_labels())
    if (l.role == role) s.insert(l.id);
  return s;
}

/// Centroid of a label in world mm.
Vec3 centroid_mm(const Phantom& p, int id) {
  const Geometry& g = p.labels.geometry();
  const uint8_t* l = p.labels.data<uint8_t>();
  Vec3 sum = Vec3::Zero();
  int64_t n = 0;
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i)
        if (l[g.linear_index(i, j, k)] == id) { sum += Vec3(double(i), double(j), double(k)); ++n; }
  EXPECT_GT(n, 0) << "label " << id;
  return g.to_world(sum / std::max<int64_t>(n, 1));
}

/// The voxel column index nearest to world coordinate `mm` along axis a.
int64_t index_near(const Geometry& g, int a, double mm) {
  return std::llround((mm - g.origin_mm[a]) / g.spacing_mm[a]);
}

class PhantomBySize : public ::testing::TestWithParam<PhantomSize> {};
INSTANTIATE_TEST_SUITE_P(Phantom, PhantomBySize, ::testing::Values(PhantomSize::Small, PhantomSize::Medium),
                         [](const auto& info) { return std::string(phantom_size_name(info.param)); });

// ---- names and grids -------------------------------------------------------------------------------------------------
TEST(PhantomSize, ParsesTheThreeNamesAndRejectsOthers) {
  EXPECT_EQ(parse_phantom_size("small"), PhantomSize::Small);
  EXPECT_EQ(parse_phantom_size("medium"), PhantomSize::Medium);
  EXPECT_EQ(parse_phantom_size("large"), PhantomSize::Large);
  try {
    parse_phantom_size("huge");
    FAIL() << "no error for 'huge'";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("huge"), std::string::npos) << m;
    EXPECT_NE(m.find("small, medium, large"), std::string::npos) << m;
  }
  EXPECT_THROW(parse_phantom_size("Small"), InputError);   // names are exact
  EXPECT_THROW(parse_phantom_size(""), InputError);
}

TEST(PhantomGeometry, SizesSpacingAndRasFrameWithoutGenerating) {
  struct Expect { PhantomSize size; Index3 dims; double spacing; double fov_z_mm; };
  for (const Expect& e : {Expect{PhantomSize::Small, {96, 96, 96}, 4.0, 384.0},
                          Expect{PhantomSize::Medium, {256, 256, 200}, 1.5, 300.0},
                          Expect{PhantomSize::Large, {512, 512, 400}, 0.75, 300.0}}) {
    const Geometry g = phantom_geometry(e.size);
    EXPECT_EQ(g.dims, e.dims);
    EXPECT_EQ(g.spacing_mm, Vec3::Constant(e.spacing));
    EXPECT_TRUE(g.direction.isIdentity());
    EXPECT_EQ(g.orientation_code(), "RAS");
    EXPECT_NO_THROW(g.validate("phantom"));
    // ≈ the same 384 × 384 mm field of view in x and y at every size, centred on the body laterally.
    for (int a = 0; a < 2; ++a) {
      EXPECT_NEAR(g.dims[a] * g.spacing_mm[a], 384.0, 1e-9);
      EXPECT_NEAR(g.origin_mm[a] + 0.5 * (g.dims[a] - 1) * g.spacing_mm[a], 0.0, 1e-9);
    }
    EXPECT_NEAR(g.dims[2] * g.spacing_mm[2], e.fov_z_mm, 1e-9);
  }
  EXPECT_EQ(phantom_cube_voxels(PhantomSize::Small), 2);
  EXPECT_EQ(phantom_cube_voxels(PhantomSize::Medium), 6);
  EXPECT_EQ(phantom_cube_voxels(PhantomSize::Large), 12);
}

TEST(PhantomLabels, TotalSegmentatorIdsRolesAndSources) {
  const auto& labels = phantom_labels();
  ASSERT_FALSE(labels.empty());
  EXPECT_EQ(labels.front().id, 0);
  EXPECT_EQ(labels.front().role, Role::Other);
  std::set<int> ids;
  std::set<std::string> names;
  for (const PhantomLabel& l : labels) {
    EXPECT_TRUE(ids.insert(l.id).second) << "duplicate id " << l.id;
    EXPECT_TRUE(names.insert(l.name).second) << "duplicate name " << l.name;
    EXPECT_GE(l.id, 0);
    EXPECT_LE(l.id, 255);
    EXPECT_FALSE(l.source.empty()) << l.name;
    EXPECT_GE(l.hu, -1000);
    EXPECT_LE(l.hu, 3071);
  }
  EXPECT_TRUE(std::is_sorted(labels.begin(), labels.end(), [](const auto& a, const auto& b) { return a.id < b.id; }));
  // TotalSegmentator v2 "total" ids (shared with scenes for real CTs) and the 200+ ids of the phantom's own.
  const std::map<std::string, int> expected = {
      {"spleen", 1}, {"kidney_right", 2}, {"kidney_left", 3}, {"liver", 5}, {"stomach", 6}, {"small_bowel", 18},
      {"colon", 20}, {"vertebrae_L3", 29}, {"aorta", 52}, {"inferior_vena_cava", 63}, {"autochthon_left", 86},
      {"autochthon_right", 87}, {"iliopsoas_left", 88}, {"iliopsoas_right", 89}, {"rib_left_10", 101},
      {"rib_left_12", 103}, {"rib_right_10", 113}, {"rib_right_12", 115}, {"skin", 200}, {"subcutaneous_fat", 201},
      {"abdominal_wall_muscle", 202}, {"intraperitoneal_fat", 203}, {"ct_table", 204}};
  for (const auto& [name, id] : expected) EXPECT_EQ(id_of(name), id) << name;
  // Roles as method.md §2 assigns them.
  for (const char* w : {"skin", "subcutaneous_fat", "abdominal_wall_muscle"}) EXPECT_EQ(label_named(w).role, Role::Wall);
  for (const char* v : {"liver", "spleen", "kidney_left", "kidney_right", "stomach", "small_bowel", "colon", "aorta",
                        "inferior_vena_cava", "intraperitoneal_fat"})
    EXPECT_EQ(label_named(v).role, Role::Viscera) << v;
  for (const char* f : {"vertebrae_L3", "rib_left_10", "autochthon_left", "ct_table"})
    EXPECT_EQ(label_named(f).role, Role::Fixed) << f;
}

// ---- determinism -------------------------------------------------------------------------------------------------
TEST_P(PhantomBySize, TwoGenerationsAreBitIdentical) {
  Progress::set_enabled(false);
  const Phantom again = make_phantom(GetParam());
  EXPECT_TRUE(again.ct.same_voxels(phantom(GetParam()).ct));
  EXPECT_TRUE(again.labels.same_voxels(phantom(GetParam()).labels));
}

TEST_P(PhantomBySize, SameVoxelsWithOneOrTwoThreads) {
  Progress::set_enabled(false);
  const int before = omp_get_max_threads();
  omp_set_num_threads(1);
  const Phantom one = make_phantom(GetParam());
  omp_set_num_threads(2);
  const Phantom two = make_phantom(GetParam());
  omp_set_num_threads(before);
  EXPECT_TRUE(one.ct.same_voxels(two.ct));
  EXPECT_TRUE(one.labels.same_voxels(two.labels));
}

// ---- voxels and grid ---------------------------------------------------------------------------------------------------
TEST_P(PhantomBySize, VoxelTypesAndGrid) {
  const Phantom& p = phantom(GetParam());
  EXPECT_EQ(p.ct.type(), VoxelType::Int16);
  EXPECT_EQ(p.labels.type(), VoxelType::UInt8);
  EXPECT_TRUE(p.ct.geometry().same_grid(phantom_geometry(GetParam())));
  EXPECT_TRUE(p.labels.geometry().same_grid(p.ct.geometry()));
  const Volume::Range r = p.ct.range();
  EXPECT_GE(r.min, -1024);
  EXPECT_LE(r.max, 3071);
  EXPECT_GT(r.max, 600) << "no bone";
}

TEST_P(PhantomBySize, OnlyKnownLabels) {
  std::set<int> known;
  for (const PhantomLabel& l : phantom_labels()) known.insert(l.id);
  for (const auto& [id, n] : label_counts(phantom(GetParam()))) EXPECT_TRUE(known.count(id)) << "label " << id;
}

TEST(PhantomSmall, EveryLabelIsPresent) {
  const auto counts = label_counts(phantom(PhantomSize::Small));
  for (const PhantomLabel& l : phantom_labels()) {
    const auto it = counts.find(l.id);
    EXPECT_TRUE(it != counts.end() && it->second > 0) << l.name << " (" << l.id << ") missing";
  }
}

// Normal adult volumes, with where the range comes from. Organ densities ≈ 1.05 g/ml.
struct VolumeRange {
  const char* name;
  double lo_ml, hi_ml;
  const char* source;
};
const VolumeRange kVolumeRanges[] = {
    {"liver", 1200, 2200, "ICRP 89 reference masses 1400 g (women) – 1800 g (men); CT volumetry 1.2–2.0 L"},
    {"spleen", 100, 400, "Prassopoulos et al., Eur Radiol 1997: normal CT splenic volume 107–314 ml"},
    {"kidney_right", 100, 250, "ICRP 89: 275–310 g for both kidneys; CT volumetry 120–200 ml each"},
    {"kidney_left", 100, 250, "ICRP 89: 275–310 g for both kidneys; CT volumetry 120–200 ml each"},
    {"pancreas", 40, 150, "ICRP 89: 120–140 g; CT volumetry 60–100 ml"},
    {"gallbladder", 15, 80, "fasting gallbladder 30–50 ml"},
    {"stomach", 200, 1000, "moderately filled stomach (wall and contents) 0.3–0.8 L"},
    {"small_bowel", 300, 1600, "≈ 3 m of 2–3 cm calibre, partly collapsed (Helander & Fändriks 2014)"},
    {"colon", 300, 1600, "≈ 1.5 m of 4–6 cm calibre, partly collapsed, rectum outside the field of view"},
    {"aorta", 40, 200, "20–24 mm diameter over 20–30 cm of the field of view"},
    {"inferior_vena_cava", 30, 200, "20–25 mm diameter over 20–25 cm"},
    {"vertebrae_L3", 25, 120, "lumbar body ≈ 45 × 35 × 27 mm plus posterior elements"},
};

TEST_P(PhantomBySize, OrganVolumesArePlausible) {
  const Phantom& p = phantom(GetParam());
  const auto counts = label_counts(p);
  for (const VolumeRange& r : kVolumeRanges) {
    const auto it = counts.find(id_of(r.name));
    const double ml = it == counts.end() ? 0.0 : it->second * voxel_ml(p);
    EXPECT_GE(ml, r.lo_ml) << r.name << ": " << r.source;
    EXPECT_LE(ml, r.hi_ml) << r.name << ": " << r.source;
  }
}

TEST_P(PhantomBySize, AnteriorWallAlongTheMidlineIs20To40mm) {
  // Skin ≈ 2 mm + subcutaneous fat 15–20 mm + linea alba/rectus: the anterior wall at the midline of a normal adult
  // is 2–4 cm. Measured from the first body voxel, along −y, to the first voxel that is not wall, at every slice
  // between the pelvic brim and the xiphoid.
  const Phantom& p = phantom(GetParam());
  const Geometry& g = p.labels.geometry();
  const std::set<int> wall = ids_with_role(Role::Wall);
  const uint8_t* l = p.labels.data<uint8_t>();
  const int64_t i0 = index_near(g, 0, 0.0);
  int checked = 0;
  for (int64_t k = 0; k < g.dims[2]; ++k) {
    const double z = g.to_world(Vec3(0, 0, double(k))).z();
    if (z < -140 || z > 100) continue;
    int64_t j = g.dims[1] - 1;
    while (j >= 0 && l[g.linear_index(i0, j, k)] == 0) --j;
    ASSERT_GE(j, 0);
    const int64_t first = j;
    while (j >= 0 && wall.count(l[g.linear_index(i0, j, k)])) --j;
    const double thickness_mm = (first - j) * g.spacing_mm.y();
    EXPECT_GE(thickness_mm, 20.0) << "z " << z;
    EXPECT_LE(thickness_mm, 40.0) << "z " << z;
    ++checked;
  }
  EXPECT_GT(checked, 10);
}

TEST_P(PhantomBySize, LiverMedianHuIsNominal) {
  const Phantom& p = phantom(GetParam());
  const uint8_t liver = static_cast<uint8_t>(id_of("liver"));
  const uint8_t* l = p.labels.data<uint8_t>();
  const int16_t* ct = p.ct.data<int16_t>();
  std::vector<int16_t> v;
  for (int64_t n = 0; n < p.ct.voxel_count(); ++n)
    if (l[n] == liver) v.push_back(ct[n]);
  ASSERT_FALSE(v.empty());
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  EXPECT_NEAR(v[v.size() / 2], label_named("liver").hu, 15.0);
}

TEST_P(PhantomBySize, GasInStomachAndBowel) {
  const Phantom& p = phantom(GetParam());
  const uint8_t* l = p.labels.data<uint8_t>();
  const int16_t* ct = p.ct.data<int16_t>();
  for (const char* name : {"stomach", "small_bowel", "colon"}) {
    const uint8_t id = static_cast<uint8_t>(id_of(name));
    int64_t gas = 0;
    for (int64_t n = 0; n < p.ct.voxel_count(); ++n)
      if (l[n] == id && ct[n] < -900) ++gas;
    EXPECT_GT(gas * voxel_ml(p), 2.0) << name << ": less than 2 ml of gas";
  }
}

TEST_P(PhantomBySize, StomachGasFloatsAnteriorly) {
  // Supine: the air-fluid level is horizontal and the gas lies on the anterior (upper) side.
  const Phantom& p = phantom(GetParam());
  const Geometry& g = p.labels.geometry();
  const uint8_t id = static_cast<uint8_t>(id_of("stomach"));
  const uint8_t* l = p.labels.data<uint8_t>();
  const int16_t* ct = p.ct.data<int16_t>();
  double gas_y = 0, fluid_y = 0;
  int64_t n_gas = 0, n_fluid = 0;
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        const int64_t n = g.linear_index(i, j, k);
        if (l[n] != id) continue;
        const double y = g.origin_mm.y() + j * g.spacing_mm.y();
        if (ct[n] < -900) { gas_y += y; ++n_gas; }
        else if (ct[n] > -100 && ct[n] < 60) { fluid_y += y; ++n_fluid; }
      }
  ASSERT_GT(n_gas, 0);
  ASSERT_GT(n_fluid, 0);
  EXPECT_GT(gas_y / n_gas, fluid_y / n_fluid + 20.0);
}

TEST_P(PhantomBySize, AtLeast60mmOfAirInFrontOfTheBody) {
  // Room for the insufflated wall to rise (a 12 mmHg pneumoperitoneum lifts the umbilicus by several cm).
  const Phantom& p = phantom(GetParam());
  const Geometry& g = p.labels.geometry();
  const uint8_t* l = p.labels.data<uint8_t>();
  int64_t min_air = g.dims[1];
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t i = 0; i < g.dims[0]; ++i) {
      int64_t air = 0;
      for (int64_t j = g.dims[1] - 1; j >= 0 && l[g.linear_index(i, j, k)] == 0; --j) ++air;
      min_air = std::min(min_air, air);
    }
  EXPECT_GE(min_air * g.spacing_mm.y(), 60.0);
}

TEST_P(PhantomBySize, WallEnclosesTheCavity) {
  // No viscera voxel has background air among its 6 neighbours: the wall (or bone/table) always lies between.
  const Phantom& p = phantom(GetParam());
  const Geometry& g = p.labels.geometry();
  const uint8_t* l = p.labels.data<uint8_t>();
  std::array<bool, 256> viscera{};
  for (int id : ids_with_role(Role::Viscera)) viscera[id] = true;
  int64_t touching = 0, viscera_voxels = 0;
  const int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  for (int64_t k = 0; k < nz; ++k)
    for (int64_t j = 0; j < ny; ++j)
      for (int64_t i = 0; i < nx; ++i) {
        const int64_t n = g.linear_index(i, j, k);
        if (!viscera[l[n]]) continue;
        ++viscera_voxels;
        const bool t = (i > 0 && l[n - 1] == 0) || (i + 1 < nx && l[n + 1] == 0) || (j > 0 && l[n - nx] == 0) ||
                       (j + 1 < ny && l[n + nx] == 0) || (k > 0 && l[n - nx * ny] == 0) ||
                       (k + 1 < nz && l[n + nx * ny] == 0);
        touching += t;
      }
  EXPECT_GT(viscera_voxels, 0);
  EXPECT_EQ(touching, 0);
}

TEST_P(PhantomBySize, OrgansOnTheirAnatomicalSides) {
  // RAS+: patient right is +x, anterior +y, superior +z.
  const Phantom& p = phantom(GetParam());
  const Vec3 liver = centroid_mm(p, id_of("liver")), spleen = centroid_mm(p, id_of("spleen"));
  const Vec3 kr = centroid_mm(p, id_of("kidney_right")), kl = centroid_mm(p, id_of("kidney_left"));
  const Vec3 aorta = centroid_mm(p, id_of("aorta")), ivc = centroid_mm(p, id_of("inferior_vena_cava"));
  const Vec3 stomach = centroid_mm(p, id_of("stomach")), l3 = centroid_mm(p, id_of("vertebrae_L3"));
  const Vec3 table = centroid_mm(p, id_of("ct_table"));
  EXPECT_GT(liver.x(), 30);
  EXPECT_LT(spleen.x(), -50);
  EXPECT_LT(stomach.x(), 0);
  EXPECT_GT(kr.x(), 30);
  EXPECT_LT(kl.x(), -30);
  EXPECT_LT(kr.z(), kl.z()) << "the right kidney lies lower (pushed down by the liver)";
  EXPECT_LT(kr.y(), l3.y() + 10) << "kidneys are posterior (retroperitoneal)";
  EXPECT_LT(kl.y(), l3.y() + 10);
  EXPECT_LT(aorta.x(), 0) << "aorta left of the midline";
  EXPECT_GT(ivc.x(), 0) << "IVC right of the midline";
  EXPECT_GT(aorta.y(), l3.y()) << "aorta anterior to the spine";
  EXPECT_GT(liver.z(), l3.z() + 50) << "liver in the upper abdomen";
  EXPECT_LT(table.y(), kr.y() - 60) << "table at the back";
  // Vertebrae in order from caudal to cranial.
  double last_z = -1e9;
  for (const char* v : {"vertebrae_L5", "vertebrae_L4", "vertebrae_L3", "vertebrae_L2", "vertebrae_L1", "vertebrae_T12",
                        "vertebrae_T11", "vertebrae_T10"}) {
    const double z = centroid_mm(p, id_of(v)).z();
    EXPECT_GT(z, last_z) << v;
    last_z = z;
  }
}

// ---- the scene -----------------------------------------------------------------------------------------------------
TEST(PhantomScene, JsonFollowsTheSchemaAndTheLabelTable) {
  for (const PhantomSize size : {PhantomSize::Small, PhantomSize::Medium, PhantomSize::Large}) {
    const std::string text = phantom_scene_json(size);
    EXPECT_NE(text.find("\n  \"inputs\""), std::string::npos) << "2-space indent";
    const nlohmann::json j = nlohmann::json::parse(text);
    EXPECT_EQ(j.at("name"), std::string("phantom-") + phantom_size_name(size));
    EXPECT_TRUE(j.at("description").is_string());
    EXPECT_EQ(j.at("inputs").at("ct"), "ct.nii.gz");
    EXPECT_EQ(j.at("inputs").at("labels"), "labels.nii.gz");
    EXPECT_EQ(j.at("inputs").at("label_names"), "label_names.csv");
    const auto& roles = j.at("roles");
    EXPECT_EQ(roles.at("source"), "labels");
    EXPECT_EQ(roles.at("unlisted_label_role"), "other");
    for (const auto& [key, role] : std::map<std::string, Role>{{"wall_labels", Role::Wall},
                                                               {"viscera_labels", Role::Viscera},
                                                               {"fixed_labels", Role::Fixed},
                                                               {"other_labels", Role::Other}}) {
      std::set<int> listed;
      for (const auto& v : roles.at(key)) listed.insert(v.get<int>());
      EXPECT_EQ(listed, ids_with_role(role)) << key;
    }
    EXPECT_EQ(roles.at("other_labels"), nlohmann::json::array({0}));
    EXPECT_EQ(j.at("mesh").at("cube_voxels"), phantom_cube_voxels(size));
    EXPECT_EQ(j.at("load").at("pressure_mmhg"), 12);
  }
}

// ---- writing the case (needs the NIfTI writer) ------------------------------------------------------------------------
TEST(PhantomCase, WritesCtLabelsAndSceneThatReadBack) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("pneumo_phantom_case_" + std::to_string(::getpid())) / "nested";
  fs::remove_all(dir.parent_path());
  const Phantom& p = phantom(PhantomSize::Small);
  write_phantom_case(p, PhantomSize::Small, dir.string());
  for (const char* f : {"ct.nii.gz", "labels.nii.gz", "label_names.csv", "scene.json"})
    EXPECT_TRUE(fs::is_regular_file(dir / f)) << f;
  // Every phantom id named, as phantom_labels() names it.
  const std::map<int, std::string> names = read_label_names((dir / "label_names.csv").string());
  EXPECT_EQ(names.size(), phantom_labels().size());
  for (const PhantomLabel& l : phantom_labels()) EXPECT_EQ(names.at(l.id), l.name);
  const Volume ct = read_volume((dir / "ct.nii.gz").string());
  const Volume labels = read_volume((dir / "labels.nii.gz").string());
  EXPECT_EQ(ct.type(), VoxelType::Int16);
  EXPECT_EQ(labels.type(), VoxelType::UInt8);
  EXPECT_TRUE(ct.geometry().same_grid(p.ct.geometry()));
  EXPECT_EQ(ct.geometry().orientation_code(), "RAS");
  EXPECT_TRUE(ct.same_voxels(p.ct));
  EXPECT_TRUE(labels.same_voxels(p.labels));
  std::ifstream in(dir / "scene.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("name"), "phantom-small");
  // Writing again over an existing case replaces it (atomic writes).
  EXPECT_NO_THROW(write_phantom_case(p, PhantomSize::Small, dir.string()));
  fs::remove_all(dir.parent_path());
}

}  // namespace
}  // namespace pneumo
