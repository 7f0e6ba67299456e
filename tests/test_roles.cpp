// Roles from a label map and the padding of the working grid (host/roles): padding lands on the
// patient's anterior, lateral, superior and inferior ends whatever the storage order and keeps every
// voxel's world position; labels map to roles through the scene; bad label maps are refused with
// messages that name the files.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>

#include "core/error.h"
#include "core/progress.h"
#include "io/volume_io.h"
#include "io_test_support.h"
#include "pipeline/scene_stages.h"
#include "report/slices.h"
#include "roles/pad.h"
#include "roles/roles.h"
#include "scene/scene.h"

using namespace pneumo;
using testing_support::ScratchDir;

namespace {

Geometry grid(const Index3& dims, const Vec3& spacing, const Mat3& dir, const Vec3& origin) {
  Geometry g;
  g.dims = dims;
  g.spacing_mm = spacing;
  g.direction = dir;
  g.origin_mm = origin;
  return g;
}

Mat3 diag(double a, double b, double c) { return Vec3(a, b, c).asDiagonal(); }

/// A volume whose voxel n holds n (int32), so a moved voxel is recognisable.
Volume numbered(const Geometry& g) {
  Volume v(g, VoxelType::Int32);
  for (int64_t n = 0; n < g.voxel_count(); ++n) v.data<int32_t>()[n] = int32_t(n);
  return v;
}

/// Every original voxel sits at (i+lo, j+lo, k+lo) in the padded volume, with its value and its
/// world position; every other voxel holds the fill.
void expect_padding_keeps_voxels(const Volume& v, const PadVoxels& p, double fill) {
  const Volume padded = pad_volume(v, p, fill);
  const Geometry& g = v.geometry();
  const Geometry& pg = padded.geometry();
  for (int a = 0; a < 3; ++a) EXPECT_EQ(pg.dims[a], g.dims[a] + p.lo[a] + p.hi[a]);
  int64_t kept = 0;
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        const Vec3 old_w = g.to_world(Vec3(i, j, k));
        const Vec3 new_w = pg.to_world(Vec3(i + p.lo[0], j + p.lo[1], k + p.lo[2]));
        ASSERT_LT((old_w - new_w).norm(), 1e-9) << i << "," << j << "," << k;
        ASSERT_EQ(padded.value(i + p.lo[0], j + p.lo[1], k + p.lo[2]), v.value(i, j, k));
        ++kept;
      }
  int64_t filled = 0;
  for (int64_t n = 0; n < padded.voxel_count(); ++n) filled += padded.value(n) == fill;
  EXPECT_EQ(filled, padded.voxel_count() - kept);
}

/// How far the world box grew towards each patient direction (mm): R, L, A, P, S, I.
std::array<double, 6> growth_mm(const Geometry& before, const Geometry& after) {
  const WorldBox b = world_box(before), a = world_box(after);
  return {a.max_mm.x() - b.max_mm.x(), b.min_mm.x() - a.min_mm.x(), a.max_mm.y() - b.max_mm.y(),
          b.min_mm.y() - a.min_mm.y(), a.max_mm.z() - b.max_mm.z(), b.min_mm.z() - a.min_mm.z()};
}

// 7 mm anterior, 5 mm lateral, 4 mm superior, 9 mm inferior.
const PadMm kPad{7.0, 5.0, 4.0, 9.0};

}  // namespace

TEST(RolesPad, RasGridPadsTheRightEndsByWholeVoxels) {
  const Geometry g = grid({10, 8, 6}, Vec3(2, 3, 4), Mat3::Identity(), Vec3(-5, 7, 11));
  const PadVoxels p = pad_voxels(g, kPad);
  // ceil(5/2) = 3 both i ends; ceil(7/3) = 3 at the anterior (high) j end; superior ceil(4/4) = 1
  // at the high k end, inferior ceil(9/4) = 3 at the low one.
  EXPECT_EQ(p.lo, (Index3{3, 0, 3}));
  EXPECT_EQ(p.hi, (Index3{3, 3, 1}));
  expect_padding_keeps_voxels(numbered(g), p, -1000);
  const auto grow = growth_mm(g, padded_geometry(g, p));
  const std::array<double, 6> expected{6, 6, 9, 0, 4, 12};
  for (int n = 0; n < 6; ++n) EXPECT_NEAR(grow[n], expected[n], 1e-9) << "direction " << "RLAPSI"[n];
}

TEST(RolesPad, LpsGridPadsTheSamePatientEnds) {
  // i towards the left, j towards the back: anterior is the low j end now.
  const Geometry g = grid({10, 8, 6}, Vec3(2, 3, 4), diag(-1, -1, 1), Vec3(40, 30, -20));
  const PadVoxels p = pad_voxels(g, kPad);
  EXPECT_EQ(p.lo, (Index3{3, 3, 3}));
  EXPECT_EQ(p.hi, (Index3{3, 0, 1}));
  expect_padding_keeps_voxels(numbered(g), p, -1000);
  const auto grow = growth_mm(g, padded_geometry(g, p));
  const std::array<double, 6> expected{6, 6, 9, 0, 4, 12};
  for (int n = 0; n < 6; ++n) EXPECT_NEAR(grow[n], expected[n], 1e-9) << "direction " << "RLAPSI"[n];
}

TEST(RolesPad, PermutedAndFlippedAxesPadTheSamePatientEnds) {
  // i towards anterior, j towards inferior, k towards the left (a sagittal acquisition, stored oddly).
  Mat3 dir;
  dir << 0, 0, -1,  //
      1, 0, 0,      //
      0, -1, 0;
  const Geometry g = grid({6, 5, 4}, Vec3(3, 4, 2), dir, Vec3(1, 2, 3));
  EXPECT_EQ(g.orientation_code(), "AIL");
  const PadVoxels p = pad_voxels(g, kPad);
  // anterior 7/3 -> 3 at the high i end; superior 4/4 -> 1 at the low j end, inferior 9/4 -> 3 at
  // the high j end; lateral 5/2 -> 3 at both k ends.
  EXPECT_EQ(p.lo, (Index3{0, 1, 3}));
  EXPECT_EQ(p.hi, (Index3{3, 3, 3}));
  expect_padding_keeps_voxels(numbered(g), p, -1);
  const auto grow = growth_mm(g, padded_geometry(g, p));
  const std::array<double, 6> expected{6, 6, 9, 0, 4, 12};
  for (int n = 0; n < 6; ++n) EXPECT_NEAR(grow[n], expected[n], 1e-9) << "direction " << "RLAPSI"[n];
}

TEST(RolesPad, NothingAskedNothingAddedAndFillMustFitTheType) {
  const Geometry g = grid({4, 4, 4}, Vec3(1, 1, 1), Mat3::Identity(), Vec3::Zero());
  EXPECT_TRUE(pad_voxels(g, PadMm{}).empty());
  const PadVoxels p = pad_voxels(g, PadMm{60, 60, 0, 0});
  EXPECT_EQ(p.lo, (Index3{60, 0, 0}));
  EXPECT_EQ(p.hi, (Index3{60, 60, 0}));
  Volume labels(g, VoxelType::UInt8);
  EXPECT_THROW(pad_volume(labels, p, -1000), std::invalid_argument);  // -1000 is no uint8
  EXPECT_NO_THROW(pad_volume(labels, p, 0));
}

// ---- roles from labels ---------------------------------------------------------------------------

namespace {

constexpr const char* kCtName = "case/ct.nii.gz";
constexpr const char* kLabelsName = "case/labels.nii.gz";

Scene labels_scene() {
  Scene s = default_scene();
  s.inputs.ct = kCtName;
  s.inputs.labels = kLabelsName;
  s.roles.source = RoleSource::Labels;
  s.roles.wall_labels = {1};
  s.roles.viscera_labels = {2, 42};   // 42 is in no map below: fine
  s.roles.fixed_labels = {7};
  s.roles.other_labels = {3};
  return s;
}

const Geometry kTiny = grid({4, 3, 2}, Vec3(1.5, 2, 2.5), Mat3::Identity(), Vec3(10, 20, 30));

Volume tiny_ct() {
  Volume ct(kTiny, VoxelType::Int16);
  for (int64_t n = 0; n < ct.voxel_count(); ++n) ct.data<int16_t>()[n] = int16_t(10 * n - 50);
  return ct;
}

/// Ids 0, 1, 2, 3, 7, 9 in a fixed pattern.
Volume tiny_labels(const Geometry& g = kTiny) {
  static const uint8_t ids[24] = {0, 1, 1, 2, 2, 2, 7, 7, 9, 0, 3, 1, 1, 1, 2, 2, 7, 9, 9, 0, 0, 3, 3, 2};
  Volume l(g, VoxelType::UInt8);
  for (int64_t n = 0; n < l.voxel_count(); ++n) l.data<uint8_t>()[n] = ids[n % 24];
  return l;
}

Role expected_role(int id, Role unlisted) {
  switch (id) {
    case 1: return Role::Wall;
    case 2: return Role::Viscera;
    case 7: return Role::Fixed;
    case 3: return Role::Other;
    default: return unlisted;
  }
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

}  // namespace

TEST(RolesLabels, EachVoxelTakesItsLabelsRole) {
  Progress::set_enabled(false);
  for (Role unlisted : {Role::Other, Role::Viscera}) {
    Scene s = labels_scene();
    s.roles.unlisted_label_role = unlisted;
    const Volume ct = tiny_ct(), labels = tiny_labels();
    ::testing::internal::CaptureStderr();
    const RoleVolume rv = assign_roles(s, ct, &labels);
    const std::string log = ::testing::internal::GetCapturedStderr();
    // 42 is listed but absent: a warning names it (a typo in a scene shows up there).
    EXPECT_NE(log.find("absent from " + std::string(kLabelsName) + ": 42"), std::string::npos) << log;
    ASSERT_TRUE(rv.geometry.same_grid(kTiny, 0.0));
    ASSERT_EQ(rv.role.size(), 24u);
    ASSERT_EQ(rv.label.size(), 24u);
    for (int64_t n = 0; n < 24; ++n) {
      const int id = labels.data<uint8_t>()[n];
      EXPECT_EQ(rv.label[n], id);
      EXPECT_EQ(rv.role[n], expected_role(id, unlisted)) << "voxel " << n << " label " << id;
      EXPECT_EQ(rv.ct.data<float>()[n], float(ct.data<int16_t>()[n]));
    }
    EXPECT_EQ(rv.count(Role::Wall), 5);
    EXPECT_EQ(rv.count(Role::Fixed), 3);
    EXPECT_EQ(rv.count(Role::Wall) + rv.count(Role::Viscera) + rv.count(Role::Fixed) + rv.count(Role::Other), 24);
    EXPECT_NEAR(rv.volume_ml(Role::Wall), 5 * 1.5 * 2 * 2.5 / 1000.0, 1e-12);
  }
}

TEST(RolesLabels, PaddingIsAirWithNoLabelAndRoleOther) {
  Scene s = labels_scene();
  s.roles.pad_anterior_mm = 4;   // 2 voxels of 2 mm at the high j end
  s.roles.unlisted_label_role = Role::Viscera;
  s.roles.other_labels = {0, 3};  // background listed as other: padding is other too
  const Volume ct = tiny_ct(), labels = tiny_labels();
  const RoleVolume rv = assign_roles(s, ct, &labels);
  EXPECT_EQ(rv.geometry.dims, (Index3{4, 5, 2}));
  EXPECT_EQ(rv.pad.hi, (Index3{0, 2, 0}));
  for (int64_t k = 0; k < 2; ++k)
    for (int64_t j = 3; j < 5; ++j)
      for (int64_t i = 0; i < 4; ++i) {
        const int64_t n = rv.geometry.linear_index(i, j, k);
        EXPECT_EQ(rv.ct.data<float>()[n], -1000.0f);
        EXPECT_EQ(rv.label[n], 0);
        EXPECT_EQ(rv.role[n], Role::Other);
      }
}

TEST(RolesLabels, LabelMapOffTheCtGridIsRefusedNamingBothFilesAndWhatDiffers) {
  const Scene s = labels_scene();
  const Volume ct = tiny_ct();
  const auto refused = [&](const Geometry& g) {
    const Volume labels = tiny_labels(g);
    return message_of([&] { assign_roles(s, ct, &labels); });
  };
  Geometry g = kTiny;
  g.dims = {4, 3, 3};
  std::string m = refused(g);
  EXPECT_NE(m.find(kCtName), std::string::npos) << m;
  EXPECT_NE(m.find(kLabelsName), std::string::npos) << m;
  EXPECT_NE(m.find("dims"), std::string::npos) << m;

  g = kTiny;
  g.origin_mm.x() += 0.01;
  m = refused(g);
  EXPECT_NE(m.find("origin"), std::string::npos) << m;

  g = kTiny;
  g.spacing_mm.z() = 2.6;
  EXPECT_NE(refused(g).find("spacing"), std::string::npos);

  g = kTiny;
  g.direction = diag(-1, 1, 1);
  EXPECT_NE(refused(g).find("direction"), std::string::npos);

  // Within 1e-3 mm is the same grid (float32 headers round origins).
  g = kTiny;
  g.origin_mm.x() += 2e-4;
  const Volume close = tiny_labels(g);
  EXPECT_NO_THROW(assign_roles(s, ct, &close));
}

TEST(RolesLabels, LabelsModeWithoutALabelMapNamesTheKeys) {
  Scene s = labels_scene();
  s.inputs.labels.clear();
  s.inputs.ct = "/nonexistent/ct.nii.gz";   // the missing labels are reported before reading the CT
  const Volume ct = tiny_ct();
  for (const std::string& m : {message_of([&] { assign_roles(s, ct, nullptr); }),
                                message_of([&] { load_roles(s); })}) {
    EXPECT_NE(m.find("roles.source"), std::string::npos) << m;
    EXPECT_NE(m.find("inputs.labels"), std::string::npos) << m;
  }
}

TEST(RolesLabels, LabelValuesMustBeIds) {
  const Scene s = labels_scene();
  const Volume ct = tiny_ct();
  Volume negative(kTiny, VoxelType::Int16);
  negative.data<int16_t>()[5] = -1;
  Volume fractional(kTiny, VoxelType::Float32);
  fractional.data<float>()[7] = 2.5f;
  Volume huge(kTiny, VoxelType::Int32);
  huge.data<int32_t>()[0] = 70000;
  for (const Volume* bad : {&negative, &fractional, &huge}) {
    const std::string m = message_of([&] { assign_roles(s, ct, bad); });
    EXPECT_NE(m.find(kLabelsName), std::string::npos) << m;
  }
  // Whole numbers stored as floats are ids. (Ids of each role list present: a list none of whose ids the
  // map holds is refused, see RolesLabels.AMappingForAnotherLabelMapIsRefused.)
  Volume whole_floats(kTiny, VoxelType::Float32);
  whole_floats.data<float>()[1] = 1.0f;
  whole_floats.data<float>()[2] = 2.0f;
  whole_floats.data<float>()[3] = 7.0f;
  const RoleVolume rv = assign_roles(s, ct, &whole_floats);
  EXPECT_EQ(rv.role[1], Role::Wall);
  EXPECT_EQ(rv.role[2], Role::Viscera);
  EXPECT_EQ(rv.role[3], Role::Fixed);
}

TEST(RolesLabels, AMappingForAnotherLabelMapIsRefused) {
  // Compared: a label map holding ids 0, 1, 2, 3, 7, 9 against scenes whose role lists miss it: a list
  // with some of its ids present is fine (a mapping for every organ of a segmentation tool, on a CT that
  // shows a few: the warning names the absent ones); a list with none present is an InputError naming the
  // label map, the list and the ids the map holds (a mapping written for another tool or id version would
  // otherwise give every voxel the wrong role in silence).
  const Volume ct = tiny_ct(), labels = tiny_labels();
  Scene s = labels_scene();
  ::testing::internal::CaptureStderr();
  EXPECT_NO_THROW(assign_roles(s, ct, &labels));   // viscera_labels = {2, 42}: 2 is there
  ::testing::internal::GetCapturedStderr();
  s.roles.viscera_labels = {40, 42};
  const std::string m = message_of([&] { assign_roles(s, ct, &labels); });
  EXPECT_EQ(m.rfind(std::string(kLabelsName) + ": ", 0), 0u) << m;
  EXPECT_NE(m.find("roles.viscera_labels (40, 42)"), std::string::npos) << m;
  EXPECT_NE(m.find("its ids: 1, 2, 3, 7, 9"), std::string::npos) << m;
}

TEST(RolesLabels, LoadRolesReadsTheScenesFiles) {
  ScratchDir dir;
  const Volume ct = tiny_ct(), labels = tiny_labels();
  write_volume(ct, dir.file("ct.nii.gz"));
  write_volume(labels, dir.file("labels.mha"));
  std::ofstream(dir.file("scene.json")) << R"({"inputs": {"ct": "ct.nii.gz", "labels": "labels.mha"},
    "roles": {"source": "labels", "wall_labels": [1], "viscera_labels": [2], "fixed_labels": [7]}})";
  const Scene s = load_scene(dir.file("scene.json"));
  const RoleVolume rv = load_roles(s);
  ASSERT_EQ(rv.role.size(), 24u);
  for (int64_t n = 0; n < 24; ++n)
    EXPECT_EQ(rv.role[n], expected_role(labels.data<uint8_t>()[n], Role::Other));
  EXPECT_TRUE(rv.geometry.same_grid(kTiny, 1e-4));
}
