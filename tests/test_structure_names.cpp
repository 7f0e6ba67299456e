// Roles by anatomy (roles/structure_names.h): what a structure's name says about its place relative to
// the peritoneum, for TotalSegmentator v1 and v2, the challenge sets' spellings and hand-made names.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "example_roles_support.h"
#include "io/label_table.h"
#include "roles/structure_names.h"

using namespace pneumo;
using namespace pneumo::testing_support;

TEST(StructureNames, EveryTotalSegmentatorClassHasAPlaceInV1AndV2) {
  for (const char* file : {"/totalsegmentator_total.csv", "/totalsegmentator_v1_total.csv"}) {
    const std::map<int, std::string> names = read_label_names(label_table_dir() + file);
    EXPECT_GE(names.size(), 104u) << file;
    for (const auto& [id, name] : names) {
      const Compartment c = compartment_of(name);
      EXPECT_NE(c, Compartment::Unknown) << file << ": " << id << " " << name;
      EXPECT_NE(c, Compartment::Tissue) << file << ": " << id << " " << name;
    }
  }
}

TEST(StructureNames, TheSameStructureHasTheSameCompartmentInBothVersions) {
  const std::map<int, std::string> v1 = read_label_names(label_table_dir() + "/totalsegmentator_v1_total.csv");
  const std::map<int, std::string> v2 = read_label_names(label_table_dir() + "/totalsegmentator_total.csv");
  std::map<std::string, Compartment> by_name;
  for (const auto& [id, name] : v2) by_name[name] = compartment_of(name);
  int shared = 0;
  for (const auto& [id, name] : v1) {
    const auto it = by_name.find(name);
    if (it == by_name.end()) continue;   // v1's heart chambers, face, pulmonary artery: v2 renamed them
    EXPECT_EQ(compartment_of(name), it->second) << name;
    ++shared;
  }
  EXPECT_GE(shared, 90);
}

TEST(StructureNames, SpellingsOfOtherToolsAndHandsMeanTheSame) {
  const std::pair<const char*, Compartment> cases[] = {
      {"Kidney Left", Compartment::Retroperitoneal},    {"kidney_L", Compartment::Retroperitoneal},
      {"LK", Compartment::Retroperitoneal},             {"right kidney", Compartment::Retroperitoneal},
      {"Right adrenal gland", Compartment::Retroperitoneal},
      {"postcava", Compartment::Retroperitoneal},       {"Inferior Vena Cava", Compartment::Retroperitoneal},
      {"Portal vein and splenic vein", Compartment::Retroperitoneal},
      {"rectum", Compartment::Retroperitoneal},         {"Gall Bladder", Compartment::Peritoneal},
      {"gallbladder", Compartment::Peritoneal},         {"Intestine", Compartment::Peritoneal},
      {"sigmoid colon", Compartment::Peritoneal},       {"LIVER", Compartment::Peritoneal},
      {"bladder", Compartment::Prevesical},             {"Urinary-Bladder", Compartment::Prevesical},
      {"Head_of_femur_L", Compartment::Fixed},          {"prostate/uterus", Compartment::Fixed},
      {"heart", Compartment::Fixed},                    {"esophagus", Compartment::Fixed},
      {"rib_right_12", Compartment::Fixed},             {"vertebrae_L5", Compartment::Fixed},
      {"rectus_abdominis_left", Compartment::AbdominalWall},
      {"subcutaneous_fat", Compartment::Tissue},        {"skeletal_muscle", Compartment::Tissue},
      {"tumour 3", Compartment::Unknown},               {"", Compartment::Unknown},
  };
  for (const auto& [name, expected] : cases)
    EXPECT_EQ(compartment_of(name), expected) << '"' << name << "\" is " << compartment_name(compartment_of(name));
}

TEST(StructureNames, TheExamplesNamesGiveTheRolesChosenByHand) {
  const std::map<int, std::string> names = read_label_names(totalseg_dir() + "/labels.csv");
  std::set<int> present;
  for (const auto& [id, name] : names) present.insert(id);
  const RolesFromNames r = roles_from_names(names);
  EXPECT_EQ(r.viscera, kHandViscera);
  EXPECT_EQ(r.wall, kHandWall);
  EXPECT_EQ(r.attached, kHandWall);   // every wall organ of the example is retroperitoneal or the bladder
  EXPECT_EQ(r.prevesical, std::vector<int>{21});
  EXPECT_EQ(r.fixed, ids_present(kHandFixed, present));
  EXPECT_EQ(r.lung, ids_present(kHandLungs, present));
  EXPECT_TRUE(r.unknown.empty());
}

TEST(StructureNames, TheScenesListsOverrideTheNames) {
  const std::map<int, std::string> names{{1, "spleen"}, {2, "kidney_right"}, {5, "liver"}, {9, "mystery"}};
  const RolesFromNames r = roles_from_names(names, {5});
  EXPECT_EQ(r.viscera, std::vector<int>{1});
  EXPECT_EQ(r.wall, std::vector<int>{2});
  EXPECT_EQ(r.unknown, std::vector<int>{9});
}

