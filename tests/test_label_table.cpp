// Label names in (a CSV), label tables out (3D Slicer's .ctbl and ITK-SNAP's label description)
// beside the deformed labels, so a user opening them sees organ names and the CO2 cavity named.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "cli_test_support.h"
#include "core/error.h"
#include "io/label_table.h"
#include "io/volume_io.h"
#include "io_test_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;

const std::string kData = std::string(PNEUMO_SOURCE_DIR) + "/data/";

TEST(LabelNames, ReadsTheTotalSegmentatorTableAndTheExamplesOwn) {
  const auto total = read_label_names(kData + "label_tables/totalsegmentator_total.csv");
  EXPECT_EQ(total.size(), 117u);
  EXPECT_EQ(total.at(5), "liver");
  EXPECT_EQ(total.at(21), "urinary_bladder");
  EXPECT_EQ(total.at(117), "costal_cartilages");
  // The example's labels.csv has more columns (voxels, volume, slices): they are ignored.
  const auto example = read_label_names(kData + "totalseg-example-ct/labels.csv");
  EXPECT_EQ(example.size(), 61u);
  for (const auto& [id, name] : example) EXPECT_EQ(total.at(id), name) << id;
}

TEST(LabelNames, BadFilesAreRefusedNamingTheFileAndLine) {
  ScratchDir d;
  const std::map<std::string, std::string> cases = {
      {"id,label\n1,liver\n", "line 1: the header needs"},
      {"label_id,name\n1,liver\nx,spleen\n", "line 3: label id \"x\" is not an integer"},
      {"label_id,name\n70000,liver\n", "line 2: label id \"70000\""},
      {"label_id,name\n1,liver\n\n1,spleen\n", "line 4: label 1 is named twice"},
      {"label_id,name\n1,\n", "line 2: label 1 has no name"},
      {"label_id,name,voxels\n1\n", "line 2: fewer columns"}};
  for (const auto& [text, message] : cases) {
    const std::string path = d.file("names.csv");
    write_bytes(path, text);
    try {
      read_label_names(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(read_label_names(d.file("missing.csv")), InputError);
}

/// Rows of a table file: the non-comment lines, split on whitespace outside quotes.
std::vector<std::vector<std::string>> rows(const std::string& path) {
  std::ifstream is(path);
  std::vector<std::vector<std::string>> out;
  std::string line;
  while (std::getline(is, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> f;
    std::istringstream ss(line);
    std::string w;
    while (ss >> std::ws && ss.peek() != EOF) {
      if (ss.peek() == '"') {
        ss.get();
        std::getline(ss, w, '"');
      } else {
        ss >> w;
      }
      f.push_back(w);
    }
    out.push_back(f);
  }
  return out;
}

TEST(LabelTables, TheWarpNamesEveryIdOfTheDeformedLabelsForSlicerAndItkSnap) {
  ScratchDir d;
  write_bytes(d.file("names.csv"), "label_id,name\n" + std::to_string(int(kTinyWall)) + ",abdominal wall\n" +
                                       std::to_string(int(kTinyViscera)) + ",small_bowel\n");
  nlohmann::json s = tiny_case_scene_json();
  s["inputs"]["label_names"] = "names.csv";
  const std::string scene = write_tiny_case(d, s);
  ASSERT_EQ(run_pneumo("-q simulate " + scene + " --out " + d.file("out")).code, 0);
  ASSERT_EQ(run_pneumo("-q warp " + scene + " --out " + d.file("out")).code, 0);
  const Volume labels = read_volume(d.file("out/deformed_labels.nii.gz"));
  std::set<int> ids = {0};
  dispatch_voxel_type(labels.type(), const_cast<void*>(labels.raw()), [&](auto* p) {
    for (int64_t n = 0; n < labels.voxel_count(); ++n) ids.insert(int(p[n]));
  });
  ASSERT_TRUE(ids.count(250)) << "the tiny case opens a cavity";
  ASSERT_TRUE(ids.count(int(kTinyFixed))) << "an id the names file leaves out";

  // 3D Slicer: "id name R G B A", names without spaces.
  const auto slicer = rows(d.file("out/deformed_labels.ctbl"));
  std::map<int, std::vector<std::string>> by_id;
  for (const auto& r : slicer) {
    ASSERT_EQ(r.size(), 6u);
    by_id[std::stoi(r[0])] = r;
    for (int c = 2; c < 6; ++c) EXPECT_TRUE(std::stoi(r[c]) >= 0 && std::stoi(r[c]) <= 255);
  }
  std::set<int> listed;
  for (const auto& [id, r] : by_id) listed.insert(id);
  EXPECT_EQ(listed, ids);
  EXPECT_EQ(by_id.at(kTinyWall)[1], "abdominal_wall");
  EXPECT_EQ(by_id.at(kTinyViscera)[1], "small_bowel");
  EXPECT_EQ(by_id.at(kTinyFixed)[1], "label_" + std::to_string(int(kTinyFixed)));
  EXPECT_EQ(by_id.at(250)[1], "CO2_cavity");
  EXPECT_EQ(by_id.at(0)[5], "0") << "background transparent";

  // ITK-SNAP: index, R, G, B, opacity, visibility, mesh visibility, quoted name.
  const auto snap = rows(d.file("out/deformed_labels_itksnap.txt"));
  std::map<int, std::string> names;
  for (const auto& r : snap) {
    ASSERT_EQ(r.size(), 8u);
    names[std::stoi(r[0])] = r[7];
    EXPECT_EQ(r[1], by_id.at(std::stoi(r[0]))[2]) << "the same colours as Slicer's table";
  }
  EXPECT_EQ(names.size(), ids.size());
  EXPECT_EQ(names.at(kTinyWall), "abdominal wall");
  EXPECT_EQ(names.at(250), "CO2 cavity");
}

TEST(LabelTables, ABadNamesFileIsRefusedBeforeTheWarp) {
  ScratchDir d;
  write_bytes(d.file("names.csv"), "label_id,name\n1,liver\n1,spleen\n");
  nlohmann::json s = tiny_case_scene_json();
  s["inputs"]["label_names"] = "names.csv";
  const std::string scene = write_tiny_case(d, s);
  const CliResult run = run_pneumo("-q run " + scene + " --out " + d.file("run"));
  EXPECT_EQ(run.code, 2) << run.err;
  EXPECT_NE(run.err.find("names.csv"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("named twice"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace pneumo
