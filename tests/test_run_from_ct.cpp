// "Run your own CT" as the README gives it: the CT and its label map on the command line, `pneumo run`,
// the report; no scene file, every default (roles from the map's own names, padding found on the CT).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "example_roles_support.h"
#include "io_test_support.h"

using namespace pneumo::testing_support;

TEST(RunFromCt, TheCtAndItsLabelsAloneGiveTheExamplesAnswer) {
  PNEUMO_REQUIRE_REAL_CT();
  ScratchDir dir;
  const std::string out = dir.file("case");
  const CliResult r = run_pneumo("-q run --ct " + example_ct_path() + " --labels " + example_labels_path() + " --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream m(out + "/metrics.json");
  const nlohmann::json metrics = nlohmann::json::parse(m);
  // scenes/totalseg_example.json, which holds the same inputs and nothing else: 44.3 mm, 2403 ml with
  // the cut faces sliding and the chest held (bench/results/2026-12-07-any-ct-cases.md). The same
  // defaults give the same answer to the rounding of the warp.
  EXPECT_NEAR(metrics["anterior_rise_mm"].get<double>(), 44.28, 0.05);
  std::ifstream u(out + "/scene_used.json");
  const nlohmann::json used = nlohmann::json::parse(u);
  EXPECT_EQ(used["roles"]["viscera_labels"], nlohmann::json(std::vector<int>(kHandViscera)));
  EXPECT_EQ(metrics["cube_edge_mm"], nlohmann::json({9.0, 9.0, 9.0}));
  // The label tables name the structures from the map's header.
  std::ifstream t(out + "/deformed_labels.ctbl");
  const std::string table((std::istreambuf_iterator<char>(t)), std::istreambuf_iterator<char>());
  EXPECT_NE(table.find("5 liver "), std::string::npos);
}

TEST(RunFromCt, NeitherASceneNorACtIsBadInputSayingWhatToGive) {
  ScratchDir dir;
  const CliResult r = run_pneumo("run --out " + dir.file("x"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--ct"), std::string::npos) << r.err;
}
