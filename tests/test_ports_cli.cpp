// `pneumo ports`: the ranked table and the heat map from a scene, end to end on the tiny case turned
// so that its wall faces anterior (the candidates lie on the anterior skin), and its refusals.
#include <gtest/gtest.h>

#include <filesystem>

#include "cli_test_support.h"
#include "stb_image_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;

/// The tiny case with its stack axis (k, back → wall → air) along world +y (anterior) and j along
/// −z: what a supine abdomen's axial slices hold, so the anterior skin is the wall's top.
std::string write_anterior_tiny_case(const ScratchDir& dir, nlohmann::json scene = tiny_case_scene_json()) {
  Volume ct = tiny_case_ct(), labels = tiny_case_labels();
  for (Volume* v : {&ct, &labels})
    v->geometry().direction << 1, 0, 0,   //
        0, 0, 1,                          //
        0, -1, 0;
  return write_tiny_case(dir, scene, ct, labels);
}

TEST(PortsCli, RanksPortsForTheVisceraAndDrawsTheHeatMap) {
  const ScratchDir dir;
  const std::string scene = write_anterior_tiny_case(dir);
  const std::string out = dir.file("ports");
  const CliResult r = run_pneumo("ports " + scene + " --target-label 2 --grid-mm 10 --size 160 --out " + out + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json t = nlohmann::json::parse(r.out);
  EXPECT_EQ(t, nlohmann::json::parse(slurp(out + "/ports.json")));   // stdout is the file
  EXPECT_EQ(t["target"]["label"], 2);
  EXPECT_EQ(t["simulation"], "solved for this ranking");
  ASSERT_GT(t["feasible_candidates"].get<int>(), 0) << t.dump(1);
  const auto& best = t["candidates"][0];
  EXPECT_EQ(best["rank"], 1);
  EXPECT_TRUE(best["feasible"].get<bool>());
  EXPECT_GT(best["score"].get<double>(), 0.0);
  EXPECT_LE(best["score"].get<double>(), 1.0);
  ASSERT_TRUE(best["skin_point_mm"].is_array());   // carried back to the CT as given
  // Through the wall: the tiny wall is 2 voxels of 5 mm, the gas under it.
  EXPECT_GT(best["wall_mm"].get<double>(), 0.0);
  EXPECT_LT(best["wall_mm"].get<double>(), 20.0);
  int w = 0, h = 0, n = 0;
  unsigned char* png = stbi_load((out + "/ports_heat_map.png").c_str(), &w, &h, &n, 3);
  ASSERT_NE(png, nullptr);
  stbi_image_free(png);
  EXPECT_EQ(w, 160);
  EXPECT_EQ(h, 120);
}

TEST(PortsCli, RefusesATargetTheLabelsLackAndKeepsAnEarlierTable) {
  const ScratchDir dir;
  const std::string scene = write_anterior_tiny_case(dir);
  const std::string out = dir.file("ports");
  const CliResult absent = run_pneumo("ports " + scene + " --target-label 9 --size 64 --out " + out);
  EXPECT_NE(absent.code, 0);
  EXPECT_NE(absent.err.find("label 9 holds no voxel"), std::string::npos) << absent.err;
  EXPECT_FALSE(std::filesystem::exists(out + "/ports.json"));
  ASSERT_EQ(run_pneumo("ports " + scene + " --target-label 2 --size 64 --out " + out).code, 0);
  const std::string first = slurp(out + "/ports.json");
  const CliResult again = run_pneumo("ports " + scene + " --target-label 2 --size 64 --out " + out);
  EXPECT_NE(again.code, 0);
  EXPECT_NE(again.err.find("--force"), std::string::npos) << again.err;
  EXPECT_EQ(slurp(out + "/ports.json"), first);
}

}  // namespace
}  // namespace pneumo
