// `pneumo render` as a user meets it, on the analytic cavity phantom written as NIfTI: every view
// kind lands where the docs say, each OpenGL back end can be chosen by flag (OSMesa included, in
// its own process since a process keeps one context), bad input exits 2 with a one-line message.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "io/volume_io.h"
#include "render_test_support.h"

namespace pneumo {
namespace {

using testing_support::run_pneumo;
using testing_support::ScratchDir;
namespace fs = std::filesystem;

// ct.nii.gz + labels.nii.gz of the cavity phantom, and a scene with one of each view kind.
void write_case(const ScratchDir& dir, const nlohmann::json& render) {
  const RenderVolume v = testing_support::make_cavity_phantom();
  Volume ct(v.geometry, VoxelType::Int16), labels(v.geometry, VoxelType::UInt8);
  for (int64_t n = 0; n < v.geometry.voxel_count(); ++n) {
    ct.data<int16_t>()[n] = int16_t(v.hu[n]);
    labels.data<uint8_t>()[n] = uint8_t(v.labels[n]);
  }
  write_volume(ct, dir.file("ct.nii.gz"));
  write_volume(labels, dir.file("labels.nii.gz"));
  nlohmann::json scene = {{"inputs", {{"ct", "ct.nii.gz"}, {"labels", "labels.nii.gz"}}}, {"render", render},
                          {"output", {{"write_depth", true}}}};
  std::ofstream(dir.file("scene.json")) << scene.dump(2);
}

nlohmann::json all_kinds() {
  return nlohmann::json::parse(R"({
    "width": 48, "height": 32,
    "cameras": [{"name": "centre", "position_mm": [0, 20, 0], "look_at_mm": [0, -35, 0]}],
    "ports": [{"name": "port", "skin_point_mm": [0, 30, 10], "target_label": 5, "insertion_mm": 5,
               "oblique_deg": 30, "lens": "fisheye", "fov_deg": 170}],
    "paths": [{"name": "fly", "frames": 3, "keyframes": [
      {"position_mm": [-10, 20, 0], "look_at_mm": [0, -35, 0]},
      {"position_mm": [10, 20, 5], "look_at_mm": [0, -35, 5]}]}]
  })");
}

TEST(RenderCli, WritesEveryViewKindWithEachBackend) {
  for (const char* backend : {"egl-surfaceless", "osmesa"}) {
    ScratchDir dir;
    write_case(dir, all_kinds());
    const auto r = run_pneumo("render " + dir.file("scene.json") + " --out " + dir.file("out") + " --backend " + backend);
    if (r.code != 0 && r.err.find("no offscreen OpenGL context") != std::string::npos)
      GTEST_SKIP() << backend << ": no context can be created here: " << r.err;
    ASSERT_EQ(r.code, 0) << backend << ": " << r.err;
    for (const char* f : {"views/centre.png", "views/centre_depth.png", "views/port.png", "views/exterior_anterior.png",
                          "views/exterior_left.png", "flythrough/fly/frame_0001.png", "flythrough/fly/frame_0003.png",
                          "render.json"})
      EXPECT_TRUE(fs::exists(dir.path() / "out" / f)) << backend << ": " << f;
    std::ifstream in(dir.file("out/render.json"));
    const auto j = nlohmann::json::parse(in);
    EXPECT_EQ(j["render"]["backend"], backend);
    EXPECT_EQ(j["views"].size(), 4u);
    EXPECT_EQ(j["deformed"], false);
  }
}

TEST(RenderCli, AFinishedRenderIsReplacedOnlyWithForce) {
  // A second render into a folder that holds one (another width here) must refuse with exit 2 and
  // leave the first views as they were; with --force it replaces them.
  ScratchDir dir;
  write_case(dir, all_kinds());
  const std::string base = "render " + dir.file("scene.json") + " --out " + dir.file("out") + " --cpu";
  ASSERT_EQ(run_pneumo(base).code, 0);
  const auto before = fs::last_write_time(dir.path() / "out" / "render.json");
  const auto again = run_pneumo(base);
  EXPECT_EQ(again.code, 2) << again.err;
  EXPECT_NE(again.err.find("already holds rendered views (render.json); use --force"), std::string::npos) << again.err;
  EXPECT_EQ(fs::last_write_time(dir.path() / "out" / "render.json"), before);
  EXPECT_EQ(run_pneumo(base + " --force").code, 0);
}

TEST(RenderCli, BadInputExitsTwoWithOneLine) {
  struct Bad { nlohmann::json render; const char* says; };
  nlohmann::json outside = all_kinds();
  outside["cameras"][0]["position_mm"] = {0, 500, 0};
  nlohmann::json no_label = all_kinds();
  no_label["ports"][0]["target_label"] = 77;
  nlohmann::json preset = all_kinds();
  preset["preset"] = "ct-bone-marrow";
  for (const Bad& b : {Bad{outside, "outside the volume"}, Bad{no_label, "labels no voxel"},
                       Bad{preset, "ct-bone-marrow"}}) {
    ScratchDir dir;
    write_case(dir, b.render);
    const auto r = run_pneumo("render " + dir.file("scene.json") + " --out " + dir.file("out"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(b.says), std::string::npos) << r.err;
  }
  ScratchDir dir;
  write_case(dir, all_kinds());
  const auto r = run_pneumo("render " + dir.file("scene.json") + " --out " + dir.file("out") + " --backend vulkan");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("osmesa"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace pneumo
