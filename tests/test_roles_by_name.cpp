// Roles by anatomy in a scene (scene/scene_roles_by_name.cpp): a scene with only its inputs gets, from
// the label map's names, the roles a planner chose by hand for the example CT, voxel for voxel, and
// the same roles whatever ids the map uses (TotalSegmentator v1's).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "core/progress.h"
#include "example_roles_support.h"
#include "io/label_table.h"
#include "io/volume_io.h"
#include "io_test_support.h"
#include "pipeline/scene_stages.h"
#include "scene/scene.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

Scene scene_of(const nlohmann::json& j) { return parse_scene(j, std::string(PNEUMO_SOURCE_DIR) + "/scenes/test.json"); }

nlohmann::json inputs_only(const std::string& labels, const std::string& names = "") {
  nlohmann::json j = {{"inputs", {{"ct", example_ct_path()}, {"labels", labels}}}, {"load", {{"pressure_mmhg", 12}}}};
  if (!names.empty()) j["inputs"]["label_names"] = names;
  return j;
}

}  // namespace

TEST(RolesByName, AnInputsOnlySceneGetsTheHandChosenLists) {
  PNEUMO_REQUIRE_REAL_CT();
  const Scene s = scene_of(inputs_only(example_labels_path()));
  // The map's header names all 117 classes; compare the ones it holds.
  std::set<int> present;
  for (const auto& [id, name] : read_label_names(totalseg_dir() + "/labels.csv")) present.insert(id);
  EXPECT_EQ(s.roles.source, RoleSource::Auto);
  EXPECT_EQ(ids_present(s.roles.viscera_labels, present), kHandViscera);
  std::vector<int> wall = kHandWall;   // and the lungs, compliant by default
  wall.insert(wall.end(), kHandLungs.begin(), kHandLungs.end());
  std::sort(wall.begin(), wall.end());
  EXPECT_EQ(ids_present(s.roles.wall_labels, present), wall);
  EXPECT_EQ(ids_present(s.mesh.attached_labels, present), kHandWall);
  EXPECT_EQ(s.roles.auto_prevesical_labels, std::vector<int>{21});
  for (int id : kHandFixed)
    EXPECT_TRUE(std::count(s.roles.fixed_labels.begin(), s.roles.fixed_labels.end(), id)) << id;
  EXPECT_EQ(s.roles.label_names.at(5), "liver");
}

TEST(RolesByName, TheScenesOwnListsAndKeysWin) {
  PNEUMO_REQUIRE_REAL_CT();
  nlohmann::json j = inputs_only(example_labels_path());
  j["roles"] = {{"viscera_labels", {2}}, {"auto_prevesical_labels", nlohmann::json::array()}};
  j["mesh"] = {{"attached_labels", {3}}};
  const Scene s = scene_of(j);
  EXPECT_EQ(s.roles.viscera_labels, (std::vector<int>{1, 2, 4, 5, 6, 18, 20}));
  EXPECT_EQ(std::count(s.roles.wall_labels.begin(), s.roles.wall_labels.end(), 2), 0);
  EXPECT_EQ(s.mesh.attached_labels, std::vector<int>{3});
  EXPECT_TRUE(s.roles.auto_prevesical_labels.empty());

  j = inputs_only(example_labels_path());
  j["roles"] = {{"by_name", false}};
  EXPECT_TRUE(scene_of(j).roles.viscera_labels.empty());
  EXPECT_TRUE(scene_of(j).mesh.attached_labels.empty());
}

TEST(RolesByName, TheEchoLeavesTheNamedIdsToTheNames) {
  // scene_used.json is the echo: the ids the names gave stay out of its lists, so running it again with
  // the lungs held (roles.compliant_lungs false) holds them, where lists it wrote would keep them wall.
  PNEUMO_REQUIRE_REAL_CT();
  nlohmann::json j = inputs_only(example_labels_path());
  j["roles"] = {{"wall_labels", {30}}};   // one id of the scene's own (sacrum) stays written
  const Scene s = scene_of(j);
  const nlohmann::json echo = s.echo();
  EXPECT_EQ(echo["roles"]["wall_labels"], nlohmann::json::array({30}));
  EXPECT_TRUE(echo["roles"]["viscera_labels"].empty());
  EXPECT_TRUE(echo["roles"]["fixed_labels"].empty());
  const Scene again = scene_of(echo);
  EXPECT_EQ(again.roles.wall_labels, s.roles.wall_labels);
  EXPECT_EQ(again.roles.viscera_labels, s.roles.viscera_labels);
  EXPECT_EQ(again.roles.fixed_labels, s.roles.fixed_labels);
  EXPECT_EQ(again.echo(), echo);
  nlohmann::json held = echo;
  held["roles"]["compliant_lungs"] = false;
  const Scene fixed = scene_of(held);
  for (int id : kHandLungs) {
    EXPECT_TRUE(std::count(fixed.roles.fixed_labels.begin(), fixed.roles.fixed_labels.end(), id)) << id;
    EXPECT_FALSE(std::count(fixed.roles.wall_labels.begin(), fixed.roles.wall_labels.end(), id)) << id;
  }
}

TEST(RolesByName, VoxelsGetTheRolesOfTheHandWrittenScene) {
  PNEUMO_REQUIRE_REAL_CT();
  Progress::set_enabled(false);
  const Volume ct = read_volume(example_ct_path());
  const Volume labels = read_volume(example_labels_path());
  nlohmann::json by_hand = inputs_only(example_labels_path());
  std::vector<int> wall = kHandWall;   // and the lungs, compliant by default
  wall.insert(wall.end(), kHandLungs.begin(), kHandLungs.end());
  by_hand["roles"] = {{"by_name", false}, {"auto_prevesical_labels", {21}}, {"viscera_labels", kHandViscera},
                      {"wall_labels", wall}, {"fixed_labels", kHandFixed}};
  const RoleVolume hand = assign_roles(scene_of(by_hand), ct, &labels);
  const RoleVolume named = assign_roles(scene_of(inputs_only(example_labels_path())), ct, &labels);
  EXPECT_TRUE(hand.role == named.role);
}

TEST(RolesByName, TheExampleRenumberedToTotalSegmentatorV1GetsTheSameRoles) {
  PNEUMO_REQUIRE_REAL_CT();
  Progress::set_enabled(false);
  ScratchDir dir;
  const Volume ct = read_volume(example_ct_path());
  const Volume v2 = read_volume(example_labels_path());
  // TotalSegmentator v1 on the same CT: its ids, and no class for what only v2 segments (the
  // spinal cord, the prostate, the costal cartilages), which v1 leaves at 0.
  const std::map<int, std::string> v2_names = read_label_names(label_table_dir() + "/totalsegmentator_total.csv");
  std::map<std::string, int> v1_ids;
  for (const auto& [id, name] : read_label_names(label_table_dir() + "/totalsegmentator_v1_total.csv")) v1_ids[name] = id;
  std::vector<uint16_t> to_v1(65536, 0);
  for (const auto& [id, name] : v2_names)
    if (v1_ids.count(name)) to_v1[std::size_t(id)] = uint16_t(v1_ids[name]);
  Volume v1(v2.geometry(), VoxelType::UInt16);
  for (int64_t i = 0; i < v2.voxel_count(); ++i) v1.data<uint16_t>()[i] = to_v1[uint16_t(v2.value(i))];
  const std::string v1_path = dir.file("seg_v1.nii.gz");
  write_volume(v1, v1_path);

  const RoleVolume a = assign_roles(scene_of(inputs_only(example_labels_path())), ct, &v2);
  const RoleVolume b = assign_roles(
      scene_of(inputs_only(v1_path, label_table_dir() + "/totalsegmentator_v1_total.csv")), ct, &v1);
  ASSERT_EQ(a.role.size(), b.role.size());
  const int64_t n = int64_t(a.role.size());   // the padded grid
  int64_t differ = 0;
  for (int64_t i = 0; i < n; ++i) {
    const uint16_t id = a.label[std::size_t(i)];
    if (id != 0 && to_v1[id] != 0) {
      EXPECT_EQ(a.role[std::size_t(i)], b.role[std::size_t(i)]) << "voxel " << i;
    }
    differ += a.role[std::size_t(i)] != b.role[std::size_t(i)];
  }
  // Voxels only v2 labels (spinal cord, prostate, cartilage) go to the HU rules under v1: a few
  // per cent of the body at most, never an organ.
  EXPECT_LT(double(differ), 0.02 * double(n));
  const auto va = a.volumes_ml(), vb = b.volumes_ml();
  EXPECT_NEAR(vb[std::size_t(Role::Viscera)], va[std::size_t(Role::Viscera)], 0.01 * va[std::size_t(Role::Viscera)]);
  EXPECT_NEAR(vb[std::size_t(Role::Wall)], va[std::size_t(Role::Wall)], 0.05 * va[std::size_t(Role::Wall)]);
}

TEST(RolesByName, LabelsModeKeepsItsListsButItsMessagesNameTheStructures) {
  PNEUMO_REQUIRE_REAL_CT();
  nlohmann::json j = inputs_only(example_labels_path());
  j["roles"] = {{"source", "labels"}, {"viscera_labels", {5}}, {"wall_labels", {2}}};
  const Scene s = scene_of(j);
  EXPECT_EQ(s.roles.viscera_labels, std::vector<int>{5});   // no lists added by name
  EXPECT_EQ(s.roles.wall_labels, std::vector<int>{2});
  EXPECT_TRUE(s.mesh.attached_labels.empty());
  EXPECT_EQ(s.roles.label_names.at(5), "liver");
}

TEST(RolesByName, ArterialContrastInTheNamedVesselsAndOrgansChangesNoRole) {
  // A contrast CT: on an arterial-phase CT the aorta reads 350-450 HU and the kidneys' cortex
  // and the spleen enhance, above the 250 HU bone rule. Structures the label map names keep the role of
  // their name whatever their HU; the aorta, IVC, portal and iliac vessels raised to 400 HU, the kidneys
  // and spleen to 260 HU, must leave every voxel's role as it was.
  PNEUMO_REQUIRE_REAL_CT();
  Progress::set_enabled(false);
  const Volume ct = read_volume(example_ct_path());
  const Volume labels = read_volume(example_labels_path());
  Volume arterial(ct.geometry(), VoxelType::Float32);
  int64_t raised = 0;
  for (int64_t n = 0; n < ct.voxel_count(); ++n) {
    const int id = int(labels.value(n));
    float hu = float(ct.value(n));
    if (id == 52 || (id >= 63 && id <= 68)) hu = 400.0f;     // aorta, IVC, portal/splenic and iliac vessels
    else if (id == 1 || id == 2 || id == 3) hu = 260.0f;     // spleen, kidneys
    raised += hu != float(ct.value(n));
    arterial.data<float>()[n] = hu;
  }
  ASSERT_GT(raised, 10000);
  const Scene s = scene_of(inputs_only(example_labels_path()));
  const RoleVolume before = assign_roles(s, ct, &labels);
  const RoleVolume after = assign_roles(s, arterial, &labels);
  EXPECT_TRUE(before.role == after.role);
}
