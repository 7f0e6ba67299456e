// "Run your own CT" as the README gives it: the CT and its label map on the command line, `pneumo run`,
// the report; no scene file, every default (roles from the map's own names, padding found on the CT).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "example_roles_support.h"
#include "io_test_support.h"
#include "scene/scene.h"

using namespace pneumo::testing_support;

TEST(RunFromCt, TheCtAndItsLabelsAloneGiveTheExamplesAnswer) {
  PNEUMO_REQUIRE_REAL_CT();
  ScratchDir dir;
  const std::string out = dir.file("case");
  const CliResult r = run_pneumo("-q run --ct " + example_ct_path() + " --labels " + example_labels_path() + " --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json metrics = nlohmann::json::parse(slurp(out + "/metrics.json"));
  // scenes/totalseg_example.json holds the same inputs and nothing else: run side by side, the same
  // defaults give the same solve (node for node, so the same rise and mesh cavity to rounding).
  const std::string scene_out = dir.file("scene");
  const CliResult s = run_pneumo("-q run " + std::string(PNEUMO_SOURCE_DIR) + "/scenes/totalseg_example.json --out " + scene_out);
  ASSERT_EQ(s.code, 0) << s.err;
  const nlohmann::json scene_metrics = nlohmann::json::parse(slurp(scene_out + "/metrics.json"));
  for (const char* key : {"anterior_rise_mm", "mesh_cavity_volume_ml", "cavity_volume_ml"})
    EXPECT_NEAR(metrics[key].get<double>(), scene_metrics[key].get<double>(), 1e-6 * scene_metrics[key].get<double>()) << key;
  // scene_used.json leaves the ids the names gave to the names (Scene::echo): read again, it gives them.
  const nlohmann::json used = nlohmann::json::parse(slurp(out + "/scene_used.json"));
  EXPECT_TRUE(used["roles"]["viscera_labels"].empty());
  EXPECT_EQ(pneumo::parse_scene(used, out + "/scene_used.json").roles.viscera_labels, kHandViscera);
  EXPECT_EQ(metrics["cube_edge_mm"], nlohmann::json({9.0, 9.0, 9.0}));
  // The label tables name the structures from the map's header.
  EXPECT_NE(slurp(out + "/deformed_labels.ctbl").find("5 liver "), std::string::npos);
}

TEST(RunFromCt, NeitherASceneNorACtIsBadInputSayingWhatToGive) {
  ScratchDir dir;
  const CliResult r = run_pneumo("run --out " + dir.file("x"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--ct"), std::string::npos) << r.err;
}
