// The meshes pneumo writes, read by VTK's own XML reader (Debian's python3-vtk9), as ParaView reads
// them: VTK 9.1 had read the former ASCII files as 0 points and 0 cells (a 4-component connectivity
// array). The counts, the cell types, every array's components and the displacement are checked
// against what the simulation reports, so a file VTK reads but misreads fails too.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_test_support.h"
#include "io_test_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;
namespace fs = std::filesystem;

/// `vtk_read_vtu.py ARGS` under the interpreter CMake found VTK for (tests/CMakeLists.txt).
CliResult read_with_vtk(const std::string& args) {
  return run_shell(std::string(PNEUMO_VTK_PYTHON) + " " + PNEUMO_SOURCE_DIR + "/tests/python/vtk_read_vtu.py " + args);
}

TEST(VtuVtk, VtksReaderLoadsBothMeshesWithEveryArray) {
  ScratchDir d;
  const std::string scene = write_tiny_case(d);
  ASSERT_EQ(run_pneumo("-q simulate " + scene + " --out " + d.file("out")).code, 0);
  const nlohmann::json metrics = nlohmann::json::parse(slurp(d.file("out/metrics.json")));
  const CliResult r = read_with_vtk(d.file("out/mesh_deformed.vtu") + " " + d.file("out/mesh_initial.vtu"));
  ASSERT_EQ(r.code, 0) << "VTK (" << PNEUMO_VTK_PYTHON << ") could not read the mesh: " << r.err;
  const nlohmann::json v = nlohmann::json::parse(r.out);
  EXPECT_EQ(v["points"], metrics["nodes"]);
  EXPECT_EQ(v["cells"], metrics["tetrahedra"]);
  EXPECT_EQ(v["cell_types"], nlohmann::json::array({10})) << "VTK_TETRA only";
  const int64_t N = metrics["nodes"], T = metrics["tetrahedra"];
  EXPECT_EQ(v["point_arrays"], (nlohmann::json{{"displacement_mm", {3, N}}, {"role", {1, N}}, {"fixed", {1, N}}}));
  EXPECT_EQ(v["cell_arrays"], (nlohmann::json{{"part", {1, T}}, {"label", {1, T}}, {"young_kpa", {1, T}}}));
  // The largest wall displacement is metrics.json's (both in mm, from the same doubles).
  EXPECT_GT(double(metrics["max_wall_displacement_mm"]), 0.1);
  EXPECT_NEAR(double(v["max_wall_displacement_mm"]), double(metrics["max_wall_displacement_mm"]), 1e-9);
  // Deformed points = rest points + displacement, to the rounding of mm in doubles.
  EXPECT_LT(double(v["max_points_minus_rest_minus_displacement_mm"]), 1e-9);
}

TEST(VtuVtk, WriteMeshesFalseWritesNone) {
  ScratchDir d;
  nlohmann::json s = tiny_case_scene_json();
  s["output"] = {{"write_meshes", false}};
  const std::string scene = write_tiny_case(d, s);
  ASSERT_EQ(run_pneumo("-q simulate " + scene + " --out " + d.file("out")).code, 0);
  EXPECT_TRUE(fs::exists(d.file("out/metrics.json")));
  EXPECT_FALSE(fs::exists(d.file("out/mesh_initial.vtu")));
  EXPECT_FALSE(fs::exists(d.file("out/mesh_deformed.vtu")));
}

}  // namespace
}  // namespace pneumo
